#pragma once
/// @file
/// `merge_results`: the results directories of a study's shards (StudyShard, `--shard i/N`)
/// joined into the one the whole study writes — the same groups, the episodes in the study's
/// order (groups, then runs, then controllers), byte for byte what a single run writes apart
/// from its wall-time columns. Episodes that no shard holds are left out: running the study on
/// the merged directory runs only those.

#include <filesystem>
#include <span>

#include "twincal/core/eigen.hpp"

namespace twincal {

struct MergeReport {
  Index planned = 0;     ///< episodes the study plans
  Index merged = 0;      ///< of those, found in a shard and written
  Index duplicates = 0;  ///< episodes found in more than one shard (the same but for wall times)
  [[nodiscard]] Index missing() const noexcept { return planned - merged; }
};

/// Writes the merge of `shards` (results directories of one study) into `out`, which must not
/// hold results yet.
/// @throws InvalidArgumentError when `shards` is empty, a shard holds no summary.json, the shards
///         were run with other groups or settings, an episode is in two shards with different
///         metrics, a shard holds an episode the study does not plan, or `out` holds results;
///         Error for a file that cannot be read or written. A failed merge leaves `out` without
///         summary.json, so it can be merged into again.
MergeReport merge_results(std::span<const std::filesystem::path> shards,
                          const std::filesystem::path& out);

}  // namespace twincal
