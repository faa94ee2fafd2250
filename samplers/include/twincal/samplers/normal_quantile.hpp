#pragma once
/// @file
/// The standard normal quantile Φ⁻¹(p) = −√2 · erfc⁻¹(2p) (Boost.Math's erfc_inv, double
/// precision throughout), compiled once in the samplers library.

namespace twincal {

/// Φ⁻¹(p) for p in (0, 1); ±infinity at p = 1 or 0 and NaN outside [0, 1] (callers clip or
/// validate first, as GaussianTransform does).
[[nodiscard]] double normal_quantile(double p) noexcept;

}  // namespace twincal
