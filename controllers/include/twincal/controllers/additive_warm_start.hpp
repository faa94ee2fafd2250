#pragma once
/// @file
/// `AdditiveWarmStart`: where a budgeted search of u0(x) (eq. 3) starts for the assembly of upper
/// part i and lower part j, from the optima already found.
///
/// For an affine twin, y(x, u) = y_U(i) + y_L(j) + B u (the MIC model, and the linearization of
/// any smooth twin), the unbounded optimum u0 = −B⁺ (y_U(i) + y_L(j)) is additive in the parts:
/// u0(i, j) = u0(i, 0) + u0(0, j) − u0(0, 0). A real twin is nearly affine in its parts, so the
/// same sum (clipped to the box) is a start a local model-based search polishes in a few
/// evaluations. The assemblies of the first row and column (i = 0 or j = 0) have no such sum:
/// they form phase 0, searched from the centre of the box (or the twin's own guess); the others
/// are phase 1. Searching phase 0 before phase 1 is an order that does not depend on how many
/// workers search or in which order within a phase, so neither do the optima.

#include <map>
#include <utility>

#include <fmt/format.h>

#include "twincal/core/eigen.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/validate.hpp"
#include "twincal/models/assembly_id.hpp"

namespace twincal {

class AdditiveWarmStart {
 public:
  /// @throws DimensionMismatchError, NonFiniteError, InvalidArgumentError (lower > upper).
  AdditiveWarmStart(VectorX lower, VectorX upper)
      : lower_(std::move(lower)), upper_(std::move(upper)) {
    require_dimension("upper", upper_.size(), lower_.size());
    require_finite("lower", lower_);
    require_finite("upper", upper_);
    if (!(lower_.array() <= upper_.array()).all()) {
      throw InvalidArgumentError("lower", "lower: an entry exceeds upper; rule: lower <= upper");
    }
  }

  /// 0 for the first row and column (no additive start), 1 for the others.
  [[nodiscard]] static int phase(const AssemblyId& assembly) noexcept {
    return assembly.upper == 0 || assembly.lower == 0 ? 0 : 1;
  }

  /// Keeps u0 of `assembly` for the starts of later ones.
  /// @throws DimensionMismatchError, NonFiniteError.
  void record(const AssemblyId& assembly, const Eigen::Ref<const VectorX>& optimum) {
    require_dimension("optimum", optimum.size(), lower_.size());
    require_finite("optimum", optimum);
    optima_.insert_or_assign(assembly, VectorX(optimum));
  }

  /// Whether `assembly` has an additive start: u0(i, 0), u0(0, j) and u0(0, 0) are recorded.
  [[nodiscard]] bool has_start(const AssemblyId& assembly) const {
    return phase(assembly) == 1 && optima_.contains({assembly.upper, 0}) &&
           optima_.contains({0, assembly.lower}) && optima_.contains({0, 0});
  }

  /// u0(i, 0) + u0(0, j) − u0(0, 0) clipped to the box, or `fallback` without those three.
  [[nodiscard]] VectorX start(const AssemblyId& assembly,
                              const Eigen::Ref<const VectorX>& fallback) const {
    if (!has_start(assembly)) return fallback;
    const VectorX sum =
        optima_.at({assembly.upper, 0}) + optima_.at({0, assembly.lower}) - optima_.at({0, 0});
    return sum.cwiseMax(lower_).cwiseMin(upper_);
  }

 private:
  VectorX lower_;
  VectorX upper_;
  std::map<AssemblyId, VectorX> optima_;
};

}  // namespace twincal
