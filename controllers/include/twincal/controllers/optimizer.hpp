#pragma once
/// @file
/// The `Optimizer` concept: a derivative-free minimizer over a box, the policy behind the
/// individualized control of Def. 2, u0(x) = argmin_u Q(x, u; θ0) (eq. 3), when a twin does not
/// know its own optimum.

#include <concepts>
#include <cstdint>
#include <functional>
#include <string>

#include <fmt/format.h>
#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/format.hpp"
#include "twincal/core/validate.hpp"

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

/// Checks the input of a search over the box [lower, upper]: bounds of start's size, all finite,
/// lower <= upper on every locator (lower < upper with `strict`, for a search whose steps scale
/// with the box's width), and start inside.
/// @throws DimensionMismatchError, NonFiniteError, InvalidArgumentError naming the entry.
inline void require_search_box(const VectorX& start, const VectorX& lower, const VectorX& upper,
                               bool strict = false) {
  const Index d = start.size();
  require_dimension("lower", lower.size(), d);
  require_dimension("upper", upper.size(), d);
  require_finite("start", start);
  require_finite("lower", lower);
  require_finite("upper", upper);
  for (Index i = 0; i < d; ++i) {
    if (strict ? !(lower(i) < upper(i)) : !(lower(i) <= upper(i))) {
      throw InvalidArgumentError(
          "lower", fmt::format("lower: entry {} is {} {} upper {}; rule: lower {} upper", i,
                               lower(i), strict ? ">=" : ">", upper(i), strict ? "<" : "<="));
    }
    require_in_range(fmt::format("start({})", i), start(i), lower(i), upper(i));
  }
}

/// require_search_box with lower < upper for a search whose steps scale with the box's width
/// (TrustRegionSearch, LeastSquaresSearch), and d >= 1.
/// @throws InvalidArgumentError for an empty start; what require_search_box throws.
inline void require_scaled_search_box(const VectorX& start, const VectorX& lower,
                                      const VectorX& upper) {
  if (start.size() == 0) throw InvalidArgumentError("start", "start: value is empty; rule: d >= 1");
  require_search_box(start, lower, upper, /*strict=*/true);
}

/// `minimize(f, start, lower, upper)` returns the best point of f in [lower, upper] it finds
/// within its budget, starting its search from `start`.
template <typename O>
concept Optimizer = requires(const O& optimizer, const Objective& objective, const VectorX& start,
                             const VectorX& lower, const VectorX& upper) {
  { optimizer.minimize(objective, start, lower, upper) } -> std::same_as<OptimizationResult>;
};

}  // namespace twincal
