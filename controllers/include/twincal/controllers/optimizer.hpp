#pragma once
/// @file
/// The `Optimizer` concept: a derivative-free minimizer over a box, the policy behind the
/// individualized control of Def. 2, u0(x) = argmin_u Q(x, u; θ0) (eq. 3), when a twin does not
/// know its own optimum.

#include <concepts>
#include <cstdint>
#include <functional>
#include <string>

#include <Eigen/Core>

#include "twincal/core/eigen.hpp"

namespace twincal {

/// f(u) for a control u; may throw (the optimizer passes the error on unchanged).
using Objective = std::function<double(const Eigen::Ref<const VectorX>&)>;

/// What an optimizer found and what it cost.
struct OptimizationResult {
  VectorX argmin;                 ///< best point found (inside the bounds)
  double minimum = 0.0;           ///< objective at argmin
  std::uint64_t evaluations = 0;  ///< objective calls made
  std::string summary;  ///< one line per phase: algorithm, evaluations, value, stop reason
};

/// `minimize(f, start, lower, upper)` returns the best point of f in [lower, upper] it finds
/// within its budget, starting its search from `start`.
template <typename O>
concept Optimizer = requires(const O& optimizer, const Objective& objective, const VectorX& start,
                             const VectorX& lower, const VectorX& upper) {
  { optimizer.minimize(objective, start, lower, upper) } -> std::same_as<OptimizationResult>;
};

}  // namespace twincal
