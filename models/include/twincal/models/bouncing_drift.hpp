#pragma once
/// @file
/// `BouncingDrift<N>`: the paper's drift scenario, eq. (15):
///   δu*_t = p_{t−1} + δu*_{t−1},   δu*_0 = 0,
///   p_t = p_{t−1}  if |(p_{t−1} + δu*_{t−1})_i| ≤ b_i for every i,   −p_{t−1} otherwise,
/// a piecewise-linear drift of constant speed |p| that turns back once it has crossed the box
/// |δu*_i| ≤ b_i. Read literally, the test is on the new offset δu*_t itself, so the offset can
/// overshoot the bound by less than one step before it returns; that is what is implemented.
/// The paper takes |p_0| = 0.03 in a random direction and b = 0.5.

#include <cmath>

#include <fmt/format.h>
#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/core/validate.hpp"

namespace twincal {

template <int N>
class BouncingDrift {
 public:
  using OffsetVector = Vector<N>;

  /// Starts at δu*_0 = 0 with step p_0 = `step` and bound b = `bound` (entries ≥ 0).
  /// @throws NonFiniteError, InvalidArgumentError, DimensionMismatchError.
  BouncingDrift(const OffsetVector& step, const OffsetVector& bound)
      : step_(step), bound_(bound), offset_(OffsetVector::Zero(step.size())) {
    require_finite("step", step_);
    require_finite("bound", bound_);
    require_dimension("bound", bound_.size(), step_.size());
    if constexpr (N != Dynamic) require_dimension("step", step_.size(), N);
    for (Index i = 0; i < bound_.size(); ++i) {
      if (bound_(i) < 0.0) {
        throw InvalidArgumentError(
            "bound", fmt::format("bound: entry {} is {}; rule: must be >= 0", i, bound_(i)));
      }
    }
  }

  /// The paper's set-up: |p_0| = `step_length` along a direction uniform on the sphere (drawn
  /// from `stream`), b_i = `bound`.
  /// @throws InvalidArgumentError for a dimension < 1, a step_length ≤ 0 or a bound < 0.
  [[nodiscard]] static BouncingDrift random(Index dimension, RandomStream& stream,
                                            double step_length = 0.03, double bound = 0.5) {
    if constexpr (N != Dynamic) require_dimension("dimension", dimension, N);
    if (dimension < 1) {
      throw InvalidArgumentError(
          "dimension", fmt::format("dimension: value is {}; rule: must be >= 1", dimension));
    }
    require_finite("step_length", step_length);
    require_positive("step_length", step_length);
    require_finite("bound", bound);
    require_non_negative("bound", bound);
    OffsetVector direction(dimension);
    double norm = 0.0;
    while (!(norm > 0.0)) {  // a zero draw has probability zero, but would have no direction
      stream.fill_normal(direction);
      norm = direction.norm();
    }
    return BouncingDrift((step_length / norm) * direction,
                         OffsetVector::Constant(dimension, bound));
  }

  [[nodiscard]] Index dimension() const noexcept { return offset_.size(); }
  [[nodiscard]] Index time() const noexcept { return time_; }
  /// δu*_t.
  [[nodiscard]] const OffsetVector& offset() const noexcept { return offset_; }
  /// p_t, the step that the next advance() takes.
  [[nodiscard]] const OffsetVector& step() const noexcept { return step_; }
  [[nodiscard]] const OffsetVector& bound() const noexcept { return bound_; }

  /// One step of eq. (15).
  void advance() noexcept {
    offset_ += step_;
    if ((offset_.cwiseAbs().array() > bound_.array()).any()) step_ = -step_;
    ++time_;
  }

 private:
  OffsetVector step_;
  OffsetVector bound_;
  OffsetVector offset_;
  Index time_ = 0;
};

}  // namespace twincal
