#pragma once
/// @file
/// `ExplorationKind`: the exploration loss of eq. (12) chosen by name at run time (in configs,
/// on the command line, from Python), with its spellings. make_exploration_loss
/// (any_exploration_loss.hpp) builds the loss of each kind.

#include <array>
#include <string_view>
#include <type_traits>

#include "twincal/core/named_enum.hpp"

namespace twincal {

/// The exploration loss of eq. (12) (the paper's is trace).
enum class ExplorationKind { trace, weighted_trace, log_det, max_eigenvalue };

/// The spellings in configs and on the command line, for to_string and parse_enum
/// (named_enum.hpp).
[[nodiscard]] constexpr auto name_table(std::type_identity<ExplorationKind>) noexcept {
  return std::to_array<NameEntry<ExplorationKind>>(
      {{ExplorationKind::trace, "trace"},
       {ExplorationKind::weighted_trace, "weighted_trace"},
       {ExplorationKind::log_det, "log_det"},
       {ExplorationKind::max_eigenvalue, "max_eigenvalue"}});
}

}  // namespace twincal
