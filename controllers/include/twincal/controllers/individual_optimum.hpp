#pragma once
/// @file
/// `IndividualOptimum<Twin, Optimizer>`: the individualized control of Def. 2,
/// u0(x) = argmin_u Q(x, u; θ0) (eq. 3), and the approximated optimal quality z*(x) = Q(x, u0).
/// A twin that knows its optimum (TwinWithOptimum) answers exactly and costs no evaluation;
/// otherwise the optimizer policy searches the twin's bounds from the centre of the box (or from
/// a start the caller gives) and the evaluations are counted. The policy is an Optimizer (one
/// control per call) or a BatchOptimizer (the twin's quality_batch: TrustRegionSearch).

#include <cstdint>
#include <utility>

#include <Eigen/Core>

#include "twincal/controllers/batch_optimizer.hpp"
#include "twincal/controllers/nlopt_optimizer.hpp"
#include "twincal/controllers/optimizer.hpp"
#include "twincal/core/eigen.hpp"
#include "twincal/core/evaluation_counter.hpp"
#include "twincal/core/validate.hpp"
#include "twincal/models/twin.hpp"

namespace twincal {

/// u0(x), z*(x) and what finding them cost.
struct IndividualControl {
  VectorX control;                ///< u0(x)
  double quality = 0.0;           ///< z*(x) = Q(x, u0)
  std::uint64_t evaluations = 0;  ///< Q evaluations spent (0 for an exact optimum)
};

template <typename O>
concept AnyOptimizer = Optimizer<O> || BatchOptimizer<O>;

template <Twin T, AnyOptimizer O = NloptOptimizer>
class IndividualOptimum {
 public:
  using Assembly = typename T::Assembly;

  /// Refers to `twin`, which must outlive this object.
  explicit IndividualOptimum(const T& twin, O optimizer = O{})
      : twin_(&twin), optimizer_(std::move(optimizer)) {}

  /// u0(x) and z*(x): exact when the twin knows them, otherwise optimized from the centre of the
  /// twin's bounds.
  [[nodiscard]] IndividualControl operator()(const Assembly& assembly) const {
    if constexpr (TwinWithOptimum<T>) {
      return {VectorX(twin_->optimum(assembly)), twin_->optimal_quality(assembly), 0};
    } else {
      const VectorX centre = 0.5 * (twin_->lower_bounds() + twin_->upper_bounds());
      return optimize(assembly, centre);
    }
  }

  /// u0(x) by the optimizer from `start`, also for a twin that knows its optimum (to measure the
  /// optimizer against the truth).
  [[nodiscard]] IndividualControl optimize(const Assembly& assembly, const VectorX& start) const {
    require_dimension("start", start.size(), twin_->control_dimension());
    if constexpr (BatchOptimizer<O>) {
      const BatchObjective objective = [&](const Eigen::Ref<const MatrixX>& controls,
                                           Eigen::Ref<VectorX> qualities) {
        twin_->quality_batch(assembly, controls, qualities);
      };
      auto result =
          optimizer_.minimize(objective, start, twin_->lower_bounds(), twin_->upper_bounds());
      return {std::move(result.argmin), result.minimum, result.evaluations};
    } else {
      const Objective objective = [&](const Eigen::Ref<const VectorX>& u) {
        return twin_->quality(assembly, u);
      };
      OptimizationResult result =
          optimizer_.minimize(objective, start, twin_->lower_bounds(), twin_->upper_bounds());
      return {std::move(result.argmin), result.minimum, result.evaluations};
    }
  }

  [[nodiscard]] const T& twin() const noexcept { return *twin_; }
  [[nodiscard]] const O& optimizer() const noexcept { return optimizer_; }

 private:
  const T* twin_;
  O optimizer_;
};

}  // namespace twincal
