#pragma once
/// @file
/// An EpisodeResult as bytes, to carry a finished episode from the process that ran it (an MPI
/// rank, distributed/) to the one that stores it. The bytes are CBOR (RFC 8949, through
/// nlohmann::json): every number reads back to the same value, NaN included, so the stored
/// files are the same as if the episode had been run where it is stored.

#include <cstdint>
#include <span>
#include <vector>

#include "twincal/experiments/episode_result.hpp"

namespace twincal {

/// The bytes of `result`: its identity, its `steps` columns of trace and its metrics.
[[nodiscard]] std::vector<std::uint8_t> encode_episode_result(const EpisodeResult& result);

/// The result that encode_episode_result wrote; the trace is sized to its `steps`.
/// @throws Error ("episode result: …") when `bytes` are not such an encoding.
[[nodiscard]] EpisodeResult decode_episode_result(std::span<const std::uint8_t> bytes);

}  // namespace twincal
