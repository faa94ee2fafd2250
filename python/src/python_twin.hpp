#pragma once
/// @file
/// `PythonTwin`: a digital twin written in Python, as models' `TwinWithOptimum` sees it. The
/// Python object provides
///   - `quality_batch(assembly, controls)`: controls is a d × k array (one control per column);
///     returns k qualities (the batch every controller step is built on);
///   - `optimum(assembly)`: u0(x) = argmin_u Q(x, u) (eq. 3), d values;
///   - `lower_bounds`, `upper_bounds`: the d locator bounds;
///   - optionally `locator_names`: d strings (default "u0", "u1", …).
/// An assembly is any Python object; twincal only passes it back to the twin.
///
/// Threads: the controllers run without the GIL; each call into the twin re-acquires it.

#include <memory>
#include <string>
#include <vector>

#include <pybind11/pybind11.h>

#include "twincal/core/eigen.hpp"

namespace twincal::python {

/// An assembly, borrowed from the Python call that proposes or observes it (the controllers
/// copy assemblies without the GIL; they keep none beyond the call).
struct PythonAssembly {
  PyObject* object = nullptr;
};

class PythonTwin {
 public:
  using Assembly = PythonAssembly;

  /// Reads the bounds and names of `twin` (with the GIL held).
  /// @throws InvalidArgumentError naming the missing or malformed attribute.
  explicit PythonTwin(pybind11::object twin);
  PythonTwin(const PythonTwin&) = delete;
  PythonTwin& operator=(const PythonTwin&) = delete;
  ~PythonTwin();

  [[nodiscard]] Index control_dimension() const noexcept { return lower_.size(); }
  [[nodiscard]] const std::vector<std::string>& locator_names() const noexcept { return names_; }
  [[nodiscard]] const VectorX& lower_bounds() const noexcept { return lower_; }
  [[nodiscard]] const VectorX& upper_bounds() const noexcept { return upper_; }
  [[nodiscard]] double quality(const Assembly& assembly,
                               const Eigen::Ref<const VectorX>& control) const;
  /// out(j) = twin.quality_batch(assembly, controls)[j]. A Python exception propagates as
  /// itself. @throws DimensionMismatchError (controls' rows, out, the twin's answer's size).
  void quality_batch(const Assembly& assembly, const Eigen::Ref<const MatrixX>& controls,
                     Eigen::Ref<VectorX> out) const;
  [[nodiscard]] VectorX optimum(const Assembly& assembly) const;
  [[nodiscard]] double optimal_quality(const Assembly& assembly) const;

  /// The Python object.
  [[nodiscard]] pybind11::object object() const;

 private:
  std::unique_ptr<pybind11::object> twin_;  // released with the GIL held (see the destructor)
  VectorX lower_;
  VectorX upper_;
  std::vector<std::string> names_;
};

}  // namespace twincal::python
