#pragma once
/// @file
/// `IndividualizedController`: Def. 2, eq. (3), the paper's baseline. Each assembly gets its own
/// optimum u0(x_t) = argmin_u Q(x_t, u; θ0) in the (uncalibrated) twin. It does not learn from
/// measurements, so it cannot diverge — nor can it correct the offset δu*.

#include <utility>

#include "twincal/controllers/individual_optimum.hpp"
#include "twincal/controllers/nlopt_optimizer.hpp"
#include "twincal/controllers/optimizer.hpp"
#include "twincal/core/eigen.hpp"
#include "twincal/models/twin.hpp"

namespace twincal {

template <Twin T, Optimizer O = NloptOptimizer>
class IndividualizedController {
 public:
  using Assembly = typename T::Assembly;
  using ControlVector = VectorX;

  explicit IndividualizedController(const T& twin, O optimizer = O{})
      : optimum_(twin, std::move(optimizer)) {}

  /// u0(x_t); also recorded with z*(x_t) in last_optimum().
  [[nodiscard]] ControlVector propose(const Assembly& assembly) {
    last_ = optimum_(assembly);
    return last_.control;
  }

  /// The baseline ignores feedback.
  void observe(const Assembly& /*assembly*/, const ControlVector& /*control*/,
               double /*z*/) const noexcept {}

  /// u0, z* and the evaluations of the last propose.
  [[nodiscard]] const IndividualControl& last_optimum() const noexcept { return last_; }

 private:
  IndividualOptimum<T, O> optimum_;
  IndividualControl last_;
};

}  // namespace twincal
