#pragma once
/// @file
/// `StudyShard`: which part of a study one job runs — episode k of the study's order (groups,
/// then runs, then controllers, counted over every planned episode whether stored or not) belongs
/// to shard k mod count. Shards of one study run side by side (a Slurm job array) into results
/// directories of their own, and `merge_results` (result_merge.hpp) joins them into the
/// directory the whole study would have written.

#include <optional>
#include <string>
#include <string_view>

#include "twincal/core/eigen.hpp"

namespace twincal {

struct StudyShard {
  /// This job's shard, 0 <= index < count.
  Index index = 0;
  /// How many shards the study is cut into; 1: the whole study.
  Index count = 1;

  [[nodiscard]] bool holds(Index episode) const noexcept { return episode % count == index; }
  [[nodiscard]] bool whole() const noexcept { return count == 1; }

  /// The canonical "field: value is V; rule: …" sentence of the first rule broken, if any.
  [[nodiscard]] std::optional<std::string> validate() const;
};

/// Reads "i/N" (e.g. "2/8": the third of eight shards), as `--shard` spells it.
/// @throws InvalidArgumentError naming `field` and the text when it is not two integers joined by
///         '/' or breaks a rule of StudyShard::validate.
[[nodiscard]] StudyShard parse_study_shard(std::string_view text, std::string_view field);

}  // namespace twincal
