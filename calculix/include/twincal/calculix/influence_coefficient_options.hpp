#pragma once
/// @file
/// `InfluenceCoefficientOptions`: how `InfluenceCoefficientTwin` linearizes its CalculiX model
/// (docs/calculix.md, "The fast linear twin"). One declaration per setting: its default and its
/// documentation.

#include <optional>
#include <string>
#include <string_view>

namespace twincal {

/// Where the influence map's coefficients come from.
enum class InfluenceLinearization {
  /// Small-displacement linear solves without contact, unit locator displacements on flat parts
  /// (the method of influence coefficients, Liu & Hu 1997): exact for the linear solve, blind to
  /// contact and to the membrane stiffening of large displacements.
  small_displacement,
  /// Central secants of the model's own solve (contact and large displacements as the twin has
  /// them) across ± `secant_step_fraction` of each locator's box width around the box's centre,
  /// and each part's response at that centre: the affine map a cell would build from its slow
  /// model over the range its adjustments use.
  secant,
};

/// "small-displacement" or "secant".
[[nodiscard]] const char* to_string(InfluenceLinearization linearization) noexcept;
/// The inverse of `to_string`; nullopt for any other text.
[[nodiscard]] std::optional<InfluenceLinearization> parse_influence_linearization(
    std::string_view text) noexcept;

struct InfluenceCoefficientOptions {
  InfluenceLinearization linearization = InfluenceLinearization::small_displacement;
  /// The secant's half step as a fraction of each locator's box width (`secant` only): ¼, the
  /// cube around u0 over which docs/models.md measures how far Q² departs from a quadratic.
  double secant_step_fraction = 0.25;

  /// One line per rule: "<field>: value is <v>; rule: <rule>".
  [[nodiscard]] std::optional<std::string> validate() const;
};

}  // namespace twincal
