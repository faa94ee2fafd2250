#pragma once
/// @file
/// The named choices of an experiment — twin case, sigma-point scheme, candidate sampler and
/// exploration loss — with their spellings in configs and on the command line.

#include <span>
#include <string>
#include <string_view>

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

/// The sigma-point scheme of the filter (the paper's UKF is merwe).
enum class FilterScheme { merwe, julier, cubature, fifth_degree, simplex };

/// Where the candidate controls of eq. (14) come from (the paper's is sobol).
enum class CandidateSampler { sobol, halton, random, latin_hypercube };

/// The exploration loss of eq. (12) (the paper's is trace).
enum class ExplorationKind { trace, weighted_trace, log_det, max_eigenvalue };

[[nodiscard]] std::string_view to_string(TwinCase value) noexcept;
[[nodiscard]] std::string_view to_string(Nonlinearity value) noexcept;
[[nodiscard]] std::string_view to_string(FilterScheme value) noexcept;
[[nodiscard]] std::string_view to_string(CandidateSampler value) noexcept;
[[nodiscard]] std::string_view to_string(ExplorationKind value) noexcept;

/// Parses a spelling; `what` names the setting in the error.
/// @throws InvalidArgumentError "<what>: is \"x\"; rule: must be one of [a, b, …]".
[[nodiscard]] TwinCase parse_twin_case(std::string_view text, std::string_view what = "case");
[[nodiscard]] Nonlinearity parse_nonlinearity(std::string_view text,
                                              std::string_view what = "nonlinearity");
[[nodiscard]] FilterScheme parse_filter_scheme(std::string_view text,
                                               std::string_view what = "filter");
[[nodiscard]] CandidateSampler parse_candidate_sampler(std::string_view text,
                                                       std::string_view what = "sampler");
[[nodiscard]] ExplorationKind parse_exploration_kind(std::string_view text,
                                                     std::string_view what = "exploration");

}  // namespace twincal
