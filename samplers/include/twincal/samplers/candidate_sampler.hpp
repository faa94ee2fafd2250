#pragma once
/// @file
/// `CandidateSampler`: the sampler of a controller's candidate controls (eq. (14)) chosen by
/// name at run time (in configs, on the command line, from Python), with its spellings.
/// AnySampler (any_sampler.hpp) builds the sampler of each kind.

#include <array>
#include <string_view>
#include <type_traits>

#include "twincal/core/named_enum.hpp"

namespace twincal {

/// Where the candidate controls of eq. (14) come from (the paper's is sobol).
enum class CandidateSampler { sobol, halton, random, latin_hypercube };

/// The spellings in configs and on the command line, for to_string and parse_enum
/// (named_enum.hpp).
[[nodiscard]] constexpr auto name_table(std::type_identity<CandidateSampler>) noexcept {
  return std::to_array<NameEntry<CandidateSampler>>(
      {{CandidateSampler::sobol, "sobol"},
       {CandidateSampler::halton, "halton"},
       {CandidateSampler::random, "random"},
       {CandidateSampler::latin_hypercube, "latin_hypercube"}});
}

}  // namespace twincal
