#pragma once
/// @file
/// `sensitivity_weights`: the diagonal W of WeightedTraceLoss inferred from the twin (Sec. 4).
///
/// Near the optimum, a miscalibration δ costs E[Q(x, u0 + δ)] − Q(x, u0) ≈ ½ tr(∇²Q · P) in
/// expected quality, so the quality-relevant size of the uncertainty P is a Hessian-weighted
/// trace. W_ii is the curvature of Q along locator i at u0(x),
///   (Q(u0 + h e_i) + Q(u0 − h e_i) − 2 Q(u0)) / h²,
/// averaged over the given assemblies and scaled to mean 1 (so that W = I is the paper's
/// unweighted loss and the scale of eq. (12) is kept). One twin batch call per assembly.

#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <Eigen/Core>

#include "twincal/controllers/individual_optimum.hpp"
#include "twincal/core/eigen.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/options.hpp"
#include "twincal/core/validate.hpp"

namespace twincal {

struct SensitivityOptions {
  double step = 0.05;  ///< h, in control units (mm)
  /// Floor of a weight relative to the largest, so a locator the twin ignores still counts a
  /// little and W stays positive.
  double floor = 1e-6;

  [[nodiscard]] std::optional<std::string> validate() const {
    return first_problem(
        {rule::positive_finite("step", step), rule::in_right_open("floor", floor, 0.0, 1.0)});
  }
};

/// W's diagonal (mean 1) from the curvature of Q at u0(x) over `assemblies`.
/// @throws InvalidArgumentError (options, no assemblies, or a twin with no curvature at all),
///         NonFiniteError (a twin value), and whatever the twin or the optimum throws.
template <Twin T, Optimizer O>
[[nodiscard]] VectorX sensitivity_weights(const IndividualOptimum<T, O>& optimum,
                                          const std::vector<typename T::Assembly>& assemblies,
                                          const SensitivityOptions& options = {}) {
  require_valid("SensitivityOptions", options);
  if (assemblies.empty()) {
    throw InvalidArgumentError("assemblies",
                               "assemblies: is empty; rule: at least one assembly is needed");
  }
  const T& twin = optimum.twin();
  const Index d = twin.control_dimension();
  const double h = options.step;
  MatrixX controls(d, 2 * d + 1);
  VectorX q(2 * d + 1);
  VectorX curvature = VectorX::Zero(d);
  for (const typename T::Assembly& assembly : assemblies) {
    const VectorX u0 = optimum(assembly).control;
    controls.colwise() = u0;
    for (Index i = 0; i < d; ++i) {
      controls(i, 1 + i) += h;
      controls(i, 1 + d + i) -= h;
    }
    twin.quality_batch(assembly, controls, q);
    require_finite("twin quality", q);
    for (Index i = 0; i < d; ++i) {
      curvature(i) += (q(1 + i) + q(1 + d + i) - 2.0 * q(0)) / (h * h);
    }
  }
  curvature /= static_cast<double>(assemblies.size());
  const double largest = curvature.maxCoeff();
  if (!(largest > 0.0)) {
    throw InvalidArgumentError(
        "twin", fmt::format("twin: largest curvature of Q over the locators is {:.3g}; rule: Q "
                            "must curve upwards along at least one locator at u0",
                            largest));
  }
  const VectorX floored = curvature.cwiseMax(options.floor * largest);
  return floored / floored.mean();
}

}  // namespace twincal
