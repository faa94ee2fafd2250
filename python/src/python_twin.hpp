#pragma once
/// @file
/// `PythonTwin`: a digital twin written in Python, as models' `TwinWithOptimum` sees it. The
/// Python object provides
///   - `quality_batch(assembly, controls)`: controls is a d × k array (one control per column);
///     returns k qualities (the batch every controller step is built on);
///   - `lower_bounds`, `upper_bounds`: the d locator bounds;
///   - optionally `optimum(assembly)`: u0(x) = argmin_u Q(x, u) (eq. 3), d values. Without it,
///     u0 is searched by NLopt (controllers' NloptOptimizer: DIRECT-L over the bounds, then
///     BOBYQA) through `quality_batch` one control at a time — thousands of calls per assembly,
///     so a twin that knows its optimum should say so;
///     With `optimum`, optionally `optimal_quality(assembly)`: z*(x) = Q(x, u0), which is
///     otherwise one more quality_batch call at u0 (twincal.BudgetedOptimum answers both from
///     one search);
///   - optionally `locator_names`: d strings (default "u0", "u1", …);
///   - optionally `deviations_batch(assembly, controls)` with `key_point_count` (m >= 1, an int
///     or a method returning one): the m × k deviations r(x, u) of the twin's key points, one
///     column per control, Q = ‖r‖ / √m. A twin that has them is a TwinWithDeviations: the
///     active controller fits its models from them by Gauss–Newton (2d + 1 calls for a Jacobian,
///     where a quadratic fit of Q² takes (d + 1)(d + 2)/2), as the CLI does for its key-point,
///     FEM and CalculiX twins (docs/controllers.md).
/// An assembly is any Python object; twincal only passes it back to the twin.
///
/// A `twincal.Twin` (native_twin.hpp) takes a fast path: the controller calls the compiled twin
/// directly, without the GIL, and gets the same numbers as through Python.
///
/// Failures: a twin that raises `twincal.TwinError` (its solver did not converge, a scan is
/// unreadable) fails as a C++ TwinError, which the controllers' failure policies handle (a
/// proposal on the default control, a dropped measurement; docs/controllers.md); any other
/// exception propagates as itself and stops the controller.
///
/// Threads: the controllers run without the GIL; each call into a Python twin re-acquires it.

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <pybind11/pybind11.h>

#include "twincal/controllers/individual_optimum.hpp"
#include "twincal/core/eigen.hpp"
#include "twincal/experiments/case_twin.hpp"
#include "twincal/models/assembly_id.hpp"
#include "twincal/models/twin.hpp"

namespace twincal::python {

/// An assembly, borrowed from the Python call that proposes or observes it (the controllers
/// copy assemblies without the GIL; they keep none beyond the call), and, for a twincal.Twin,
/// the AssemblyId it spells (PythonTwin::borrow).
struct PythonAssembly {
  PyObject* object = nullptr;
  AssemblyId native;
};

class PythonTwin {
 public:
  using Assembly = PythonAssembly;
  /// A PythonAssembly borrows its object for one call (models/kept_assemblies.hpp).
  static constexpr bool borrows_assemblies = true;

  /// Reads the bounds and names of `twin` (with the GIL held).
  /// @throws InvalidArgumentError naming the missing or malformed attribute.
  explicit PythonTwin(pybind11::object twin);
  PythonTwin(const PythonTwin&) = delete;
  PythonTwin& operator=(const PythonTwin&) = delete;
  ~PythonTwin();

  /// `assembly` as the controllers pass it (with the GIL held).
  /// @throws InvalidArgumentError for a twincal.Twin that has no such assembly.
  [[nodiscard]] PythonAssembly borrow(pybind11::handle assembly) const;

  [[nodiscard]] Index control_dimension() const noexcept { return lower_.size(); }
  [[nodiscard]] const std::vector<std::string>& locator_names() const noexcept { return names_; }
  [[nodiscard]] const VectorX& lower_bounds() const noexcept { return lower_; }
  [[nodiscard]] const VectorX& upper_bounds() const noexcept { return upper_; }
  [[nodiscard]] double quality(const Assembly& assembly,
                               const Eigen::Ref<const VectorX>& control) const;
  /// out(j) = twin.quality_batch(assembly, controls)[j]. @throws TwinError for a
  /// twincal.TwinError the twin raised (another Python exception propagates as itself);
  /// DimensionMismatchError (controls' rows, out, the twin's answer's size).
  void quality_batch(const Assembly& assembly, const Eigen::Ref<const MatrixX>& controls,
                     Eigen::Ref<VectorX> out) const;
  /// twin.optimum(assembly), or NLopt's search when the twin has none (remembered until the
  /// next borrow(), so that optimum and optimal_quality search once per controller call).
  [[nodiscard]] VectorX optimum(const Assembly& assembly) const;
  [[nodiscard]] double optimal_quality(const Assembly& assembly) const;
  /// Whether the twin provides optimum(assembly) (else NLopt searches it).
  [[nodiscard]] bool has_optimum() const noexcept { return has_optimum_; }
  /// m, the key points of deviations_batch; 0 for a twin that answers only Q.
  [[nodiscard]] Index key_point_count() const noexcept { return key_points_; }
  /// out.col(j) = twin.deviations_batch(assembly, controls)[:, j] (m × k). Failures as
  /// quality_batch's.
  /// @throws InvalidArgumentError (field "deviations") for a twin that answers only Q;
  ///         DimensionMismatchError (controls, out, the twin's answer's shape).
  void deviations_batch(const Assembly& assembly, const Eigen::Ref<const MatrixX>& controls,
                        Eigen::Ref<MatrixX> out) const;

  /// The Python object.
  [[nodiscard]] pybind11::object object() const;

 private:
  struct SearchedOptimum {
    PyObject* assembly = nullptr;  // borrowed for one propose/observe call (borrow() forgets it)
    IndividualControl result;
  };

  // u0 and z* of `assembly` by NLopt, searched once per call of a controller.
  [[nodiscard]] const IndividualControl& searched_optimum(const Assembly& assembly) const;

  std::unique_ptr<pybind11::object> twin_;  // released with the GIL held (see the destructor)
  std::shared_ptr<const CaseTwin> native_;  // set for a twincal.Twin: the fast path
  bool has_optimum_ = true;
  bool has_optimal_quality_ = false;  // twin.optimal_quality(assembly), beside its optimum
  Index key_points_ = 0;
  mutable std::optional<SearchedOptimum> searched_;
  VectorX lower_;
  VectorX upper_;
  std::vector<std::string> names_;
};

static_assert(TwinWithOptimum<PythonTwin> && TwinWithDeviations<PythonTwin>);

}  // namespace twincal::python
