#pragma once
/// @file
/// `DeviationNonlinearity`: what a KeyPointTwin (key_point_twin.hpp) adds to the affine
/// deviations of an assembly's key points, r = a(x) + B u, before it takes their RMS — the part of
/// a real twin that makes Q² something other than a quadratic in u (sheet-to-sheet contact,
/// stiffening under large adjustments, the kinks of a solver's active sets).

#include <cmath>
#include <concepts>
#include <string>
#include <string_view>

#include <fmt/format.h>
#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/random_stream.hpp"

namespace twincal {

/// - `apply(u, e, Be, r)`: changes the affine deviations r = B e + w(x) (m entries) in place,
///   given the control u, its error e = u − a(x) from the affine optimum (d entries each) and how
///   far the control moved the key points from there, B e (m entries). Must be a pure function of
///   its arguments (twins are called from several threads).
/// - `name()`: the nonlinearity's name in the CLI (`--nonlinearity`).
template <typename T>
concept DeviationNonlinearity = requires(const T& nonlinearity,
                                         const Eigen::Ref<const VectorX>& control,
                                         const Eigen::Ref<const VectorX>& error,
                                         const Eigen::Ref<const VectorX>& moved,
                                         Eigen::Ref<VectorX> deviations) {
  nonlinearity.apply(control, error, moved, deviations);
  { T::name() } -> std::convertible_to<std::string_view>;
};

/// The nonlinearities' common rule on their strength s: finite, >= 0 and <= `largest`.
/// @throws InvalidArgumentError naming "strength", its value and `rule` (what s scales).
inline void require_strength(double strength, double largest, std::string_view rule) {
  if (strength >= 0.0 && strength <= largest && std::isfinite(strength)) return;
  throw InvalidArgumentError("strength",
                             fmt::format("strength: value is {}; rule: {}", strength, rule));
}

/// Where a nonlinearity draws from: the substream of `stream` named `name` (its name()), once its
/// strength passed require_strength(strength, largest, rule), so that a bad strength draws
/// nothing.
/// @throws InvalidArgumentError naming "strength".
[[nodiscard]] inline RandomStream nonlinearity_draws(const RandomStream& stream,
                                                     std::string_view name, double strength,
                                                     double largest, std::string_view rule) {
  require_strength(strength, largest, rule);
  return stream.substream(name);
}

}  // namespace twincal
