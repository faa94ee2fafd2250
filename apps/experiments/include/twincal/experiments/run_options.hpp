#pragma once
/// @file
/// `RunOptions`: how run_experiments executes a study — worker threads and the progress line.
/// They do not change any result.

#include <optional>
#include <string>

#include <fmt/format.h>

#include "twincal/core/eigen.hpp"

namespace twincal {

struct RunOptions {
  /// Worker threads; 0: all cores (std::thread::hardware_concurrency).
  Index threads = 0;
  /// Show the progress line (when standard error is a terminal).
  bool progress = true;

  [[nodiscard]] std::optional<std::string> validate() const {
    if (threads < 0) {
      return fmt::format("threads is {}; rule: must be >= 0 (0: all cores)", threads);
    }
    return std::nullopt;
  }
};

}  // namespace twincal
