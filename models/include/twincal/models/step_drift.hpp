#pragma once
/// @file
/// `StepDrift<N>`: an abrupt change, δu*_t = `before` for t < `step_time` and `after` from then
/// on (a locator knocked out of place, a re-mounted fixture): the case where a slowly adapting
/// filter must catch up.

#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/validate.hpp"

namespace twincal {

template <int N>
class StepDrift {
 public:
  using OffsetVector = Vector<N>;

  /// @throws NonFiniteError, DimensionMismatchError, InvalidArgumentError (step_time < 0).
  StepDrift(const OffsetVector& before, const OffsetVector& after, Index step_time)
      : before_(before), after_(after), step_time_(step_time) {
    require_finite("before", before_);
    require_finite("after", after_);
    require_dimension("after", after_.size(), before_.size());
    require_non_negative("step_time", static_cast<double>(step_time));
  }

  [[nodiscard]] Index dimension() const noexcept { return before_.size(); }
  [[nodiscard]] Index time() const noexcept { return time_; }
  [[nodiscard]] Index step_time() const noexcept { return step_time_; }
  /// δu*_t.
  [[nodiscard]] const OffsetVector& offset() const noexcept {
    return time_ < step_time_ ? before_ : after_;
  }
  void advance() noexcept { ++time_; }

 private:
  OffsetVector before_;
  OffsetVector after_;
  Index step_time_;
  Index time_ = 0;
};

}  // namespace twincal
