#pragma once
/// @file
/// `ConstantDrift<N>`: a fixed miscalibration δu*_t = δu* (eq. 4 with a constant offset), the
/// scenario in which the filter's estimate should converge.

#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/validate.hpp"

namespace twincal {

template <int N>
class ConstantDrift {
 public:
  using OffsetVector = Vector<N>;

  /// @throws NonFiniteError for a non-finite `offset`.
  explicit ConstantDrift(const OffsetVector& offset) : offset_(offset) {
    require_finite("offset", offset_);
  }

  [[nodiscard]] Index dimension() const noexcept { return offset_.size(); }
  [[nodiscard]] Index time() const noexcept { return time_; }
  /// δu*_t = δu*.
  [[nodiscard]] const OffsetVector& offset() const noexcept { return offset_; }
  void advance() noexcept { ++time_; }

 private:
  OffsetVector offset_;
  Index time_ = 0;
};

}  // namespace twincal
