#pragma once
/// @file
/// `Drift`: a scenario for the plant's true locator offset δu*_t (the quantity the filter
/// estimates). A drift starts at t = 0 with δu*_0, reports the current offset and steps t → t+1.
/// The scenarios: BouncingDrift (eq. 15), BrownianDrift (eq. 5c), StepDrift, ConstantDrift.
/// Random scenarios draw only from the RandomStream they are given, so a seed reproduces them.

#include <concepts>

#include "twincal/core/eigen.hpp"

namespace twincal {

template <typename D>
concept Drift = requires(D drift, const D& const_drift) {
  { const_drift.dimension() } -> std::convertible_to<Index>;
  { const_drift.time() } -> std::convertible_to<Index>;      ///< t
  { const_drift.offset() } -> std::convertible_to<VectorX>;  ///< δu*_t
  drift.advance();                                           ///< t → t + 1
};

}  // namespace twincal
