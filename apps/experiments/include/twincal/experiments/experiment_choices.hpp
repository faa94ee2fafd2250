#pragma once
/// @file
/// The named cases of an experiment — the twin case and the analytic twin's nonlinearity — with
/// their spellings in configs and on the command line. The other named choices live with what
/// they choose: FilterScheme (filters/filter_scheme.hpp), CandidateSampler
/// (samplers/candidate_sampler.hpp), ExplorationKind (controllers/exploration_kind.hpp).

#include <array>
#include <string_view>
#include <type_traits>

#include "twincal/core/named_enum.hpp"

namespace twincal {

/// The twin an experiment runs on: the paper's car body (Sec. 3.1) or car door (Sec. 3.2) on
/// the open FEM twin, or the analytic RMS-quadratic twin of any dimension. body_contact and
/// door_contact ("body-contact", "door-contact") are the same FEM cases (same parts, seeds and
/// locators A, B, C) with sheet-to-sheet contact in the flange, so Q² is piecewise quadratic
/// (sheet_metal/contact_sheet_metal_twin.hpp).
enum class TwinCase { body, door, analytic, external, body_contact, door_contact };
/// What the analytic case adds to its affine key-point deviations (models/key_point_twin.hpp):
/// none keeps the RMS-quadratic twin; contact, stiffening and kink make Q² non-quadratic.
enum class Nonlinearity { none, contact, stiffening, kink };

/// The spellings in configs and on the command line, for to_string and parse_enum
/// (named_enum.hpp).
[[nodiscard]] constexpr auto name_table(std::type_identity<TwinCase>) noexcept {
  return std::to_array<NameEntry<TwinCase>>({{TwinCase::body, "body"},
                                             {TwinCase::door, "door"},
                                             {TwinCase::analytic, "analytic"},
                                             {TwinCase::external, "external"},
                                             {TwinCase::body_contact, "body-contact"},
                                             {TwinCase::door_contact, "door-contact"}});
}
[[nodiscard]] constexpr auto name_table(std::type_identity<Nonlinearity>) noexcept {
  return std::to_array<NameEntry<Nonlinearity>>({{Nonlinearity::none, "none"},
                                                 {Nonlinearity::contact, "contact"},
                                                 {Nonlinearity::stiffening, "stiffening"},
                                                 {Nonlinearity::kink, "kink"}});
}

}  // namespace twincal
