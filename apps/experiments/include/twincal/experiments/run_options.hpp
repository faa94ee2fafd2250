#pragma once
/// @file
/// `RunOptions`: how run_experiments executes a study — worker threads, the shard and the
/// progress line. They do not change any result: a shard runs a part of the study, and the
/// shards' directories merged (result_merge.hpp) are the whole study's.

#include <optional>
#include <string>

#include <fmt/format.h>

#include "twincal/core/eigen.hpp"
#include "twincal/core/options.hpp"
#include "twincal/experiments/study_shard.hpp"

namespace twincal {

struct RunOptions {
  /// Worker threads; 0: all cores (std::thread::hardware_concurrency).
  Index threads = 0;
  /// Show the progress line (when standard error is a terminal).
  bool progress = true;
  /// The part of the study to run (StudyShard: episode k belongs to shard k mod count).
  StudyShard shard;

  [[nodiscard]] std::optional<std::string> validate() const {
    return first_problem(
        {rule::check(threads >= 0, "threads", threads, "must be >= 0 (0: all cores)"),
         rule::nested("shard", shard)});
  }
};

}  // namespace twincal
