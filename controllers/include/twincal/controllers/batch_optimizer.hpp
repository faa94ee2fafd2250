#pragma once
/// @file
/// The `BatchOptimizer` concept: a derivative-free minimizer over a box that asks for its
/// objective a batch of points at a time. A twin that costs seconds per call can answer a batch
/// faster than its points one by one — spread over a pool's workers, or one solver run for
/// several controls — so a search of eq. (3) that batches its calls waits fewer times on the
/// twin (docs/benchmarks.md, "Budgeted u0").

#include <concepts>
#include <cstdint>
#include <functional>

#include <Eigen/Core>

#include "twincal/core/eigen.hpp"

namespace twincal {

/// f at each column of `points`, into `values` (one entry per column); may throw (the optimizer
/// passes the error on unchanged). A non-finite value marks a point the objective could not
/// evaluate (a solver that did not converge).
using BatchObjective =
    std::function<void(const Eigen::Ref<const MatrixX>& points, Eigen::Ref<VectorX> values)>;

/// `minimize(f, start, lower, upper)` returns (at least) the best point of f in [lower, upper]
/// it evaluated (`argmin`, `minimum`) and the evaluations it made, starting from `start`.
template <typename O>
concept BatchOptimizer = requires(const O& optimizer, const BatchObjective& objective,
                                  const VectorX& start, const VectorX& lower,
                                  const VectorX& upper) {
  { optimizer.minimize(objective, start, lower, upper).argmin } -> std::convertible_to<VectorX>;
  { optimizer.minimize(objective, start, lower, upper).minimum } -> std::convertible_to<double>;
  {
    optimizer.minimize(objective, start, lower, upper).evaluations
    } -> std::convertible_to<std::uint64_t>;
};

}  // namespace twincal
