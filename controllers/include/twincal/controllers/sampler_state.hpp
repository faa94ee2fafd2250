#pragma once
/// @file
/// Where a candidate sampler of eq. (14) is in its sequence, as JSON, for controller snapshots:
/// `save_sampler(s)` and `restore_sampler(s, saved)` for twincal's samplers (found by ADL), and
/// the concept `SnapshotSampler`. Sobol and Halton are their seed and position (restored by
/// seek, not by drawing); PseudoRandom and LatinHypercube are their random stream (engine state
/// included); AnySampler is the sampler it wraps. Restored into a sampler of the same kind,
/// dimension and options, the next points are bit for bit the saved sampler's.

#include <concepts>
#include <cstdint>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "twincal/controllers/controller_state_json.hpp"
#include "twincal/core/error.hpp"
#include "twincal/filters/filter_state_json.hpp"
#include "twincal/samplers/any_sampler.hpp"
#include "twincal/samplers/halton.hpp"
#include "twincal/samplers/latin_hypercube.hpp"
#include "twincal/samplers/pseudo_random.hpp"
#include "twincal/samplers/sobol.hpp"

namespace twincal {

/// A Sobol sequence: its seed (the randomization) and position().
[[nodiscard]] inline nlohmann::json save_sampler(const Sobol& sampler) {
  return {{"format", "twincal.sobol"},
          {"dimension", sampler.dimension()},
          {"seed", sampler.options().seed},
          {"position", sampler.position()}};
}

/// @throws InvalidArgumentError (format, fields, a position past the sequence),
///         DimensionMismatchError; the sampler unchanged.
inline void restore_sampler(Sobol& sampler, const nlohmann::json& saved) {
  json_state::require_header(saved, "twincal.sobol", sampler.dimension());
  const std::uint64_t seed = json_state::read_count(saved, "seed");
  const std::uint64_t position = json_state::read_count(saved, "position");
  if (position > sampler.size()) {
    throw InvalidArgumentError(
        "position", fmt::format("position: is {}; rule: must be <= the sequence's {} points",
                                position, sampler.size()));
  }
  if (seed != sampler.options().seed) sampler.seed(seed);
  sampler.seek(position);
}

/// A Halton sequence: its seed (the permutations) and position().
[[nodiscard]] inline nlohmann::json save_sampler(const Halton& sampler) {
  return {{"format", "twincal.halton"},
          {"dimension", sampler.dimension()},
          {"seed", sampler.options().seed},
          {"position", sampler.position()}};
}

/// @throws InvalidArgumentError, DimensionMismatchError; the sampler unchanged.
inline void restore_sampler(Halton& sampler, const nlohmann::json& saved) {
  json_state::require_header(saved, "twincal.halton", sampler.dimension());
  const std::uint64_t seed = json_state::read_count(saved, "seed");
  const std::uint64_t position = json_state::read_count(saved, "position");
  if (seed != sampler.options().seed) sampler.seed(seed);
  sampler.seek(position);
}

/// Independent uniform points: the stream they come from.
[[nodiscard]] inline nlohmann::json save_sampler(const PseudoRandom& sampler) {
  return {{"format", "twincal.pseudo_random"},
          {"dimension", sampler.dimension()},
          {"stream", json_state::random_stream_to_json(sampler.stream())}};
}

/// @throws InvalidArgumentError, DimensionMismatchError; the sampler unchanged.
inline void restore_sampler(PseudoRandom& sampler, const nlohmann::json& saved) {
  json_state::require_header(saved, "twincal.pseudo_random", sampler.dimension());
  sampler.set_stream(json_state::read_random_stream(json_state::field(saved, "stream"), "stream"));
}

/// Latin hypercube designs: the stream they come from.
[[nodiscard]] inline nlohmann::json save_sampler(const LatinHypercube& sampler) {
  return {{"format", "twincal.latin_hypercube"},
          {"dimension", sampler.dimension()},
          {"stream", json_state::random_stream_to_json(sampler.stream())}};
}

/// @throws InvalidArgumentError, DimensionMismatchError; the sampler unchanged.
inline void restore_sampler(LatinHypercube& sampler, const nlohmann::json& saved) {
  json_state::require_header(saved, "twincal.latin_hypercube", sampler.dimension());
  sampler.set_stream(json_state::read_random_stream(json_state::field(saved, "stream"), "stream"));
}

/// The wrapped sampler's save_sampler, whose format names the kind.
[[nodiscard]] inline nlohmann::json save_sampler(const AnySampler& sampler) {
  return sampler.visit([](const auto& s) { return save_sampler(s); });
}

/// Restores a save_sampler of an AnySampler of the same kind and dimension.
/// @throws InvalidArgumentError (another kind: its format; a field), DimensionMismatchError;
///         the sampler unchanged.
inline void restore_sampler(AnySampler& sampler, const nlohmann::json& saved) {
  sampler.visit([&saved](auto& s) { restore_sampler(s, saved); });
}

/// A sampler whose position can be saved and restored (see the file comment).
template <typename S>
concept SnapshotSampler = requires(const S& sampler, S& target, const nlohmann::json& saved) {
  { save_sampler(sampler) } -> std::same_as<nlohmann::json>;
  restore_sampler(target, saved);
};

static_assert(SnapshotSampler<Sobol> && SnapshotSampler<Halton>);
static_assert(SnapshotSampler<PseudoRandom> && SnapshotSampler<LatinHypercube>);
static_assert(SnapshotSampler<AnySampler>);

}  // namespace twincal
