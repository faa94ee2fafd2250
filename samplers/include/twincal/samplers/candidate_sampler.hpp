#pragma once
/// @file
/// `CandidateSampler`: the sampler of a controller's candidate controls (eq. (14)) chosen by
/// name at run time (in configs, on the command line, from Python), with its spellings.
/// AnySampler (any_sampler.hpp) builds the sampler of each kind.

#include <array>
#include <string_view>

#include "twincal/core/name_table.hpp"

namespace twincal {

/// Where the candidate controls of eq. (14) come from (the paper's is sobol).
enum class CandidateSampler { sobol, halton, random, latin_hypercube };

/// The spellings in configs and on the command line (name_table.hpp).
inline constexpr auto candidate_sampler_names = std::to_array<NameEntry<CandidateSampler>>(
    {{CandidateSampler::sobol, "sobol"},
     {CandidateSampler::halton, "halton"},
     {CandidateSampler::random, "random"},
     {CandidateSampler::latin_hypercube, "latin_hypercube"}});

[[nodiscard]] constexpr std::string_view to_string(CandidateSampler value) noexcept {
  return name_of(candidate_sampler_names, value);
}

/// Parses a spelling; `what` names the setting in the error.
/// @throws InvalidArgumentError "<what>: is \"x\"; rule: must be one of [a, b, …]".
[[nodiscard]] inline CandidateSampler parse_candidate_sampler(std::string_view text,
                                                              std::string_view what = "sampler") {
  return parse_name(candidate_sampler_names, text, what);
}

}  // namespace twincal
