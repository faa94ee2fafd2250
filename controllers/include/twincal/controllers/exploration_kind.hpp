#pragma once
/// @file
/// `ExplorationKind`: the exploration loss of eq. (12) chosen by name at run time (in configs,
/// on the command line, from Python), with its spellings. make_exploration_loss
/// (any_exploration_loss.hpp) builds the loss of each kind.

#include <array>
#include <string_view>

#include "twincal/core/name_table.hpp"

namespace twincal {

/// The exploration loss of eq. (12) (the paper's is trace).
enum class ExplorationKind { trace, weighted_trace, log_det, max_eigenvalue };

/// The spellings in configs and on the command line (name_table.hpp).
inline constexpr auto exploration_kind_names = std::to_array<NameEntry<ExplorationKind>>(
    {{ExplorationKind::trace, "trace"},
     {ExplorationKind::weighted_trace, "weighted_trace"},
     {ExplorationKind::log_det, "log_det"},
     {ExplorationKind::max_eigenvalue, "max_eigenvalue"}});

[[nodiscard]] constexpr std::string_view to_string(ExplorationKind value) noexcept {
  return name_of(exploration_kind_names, value);
}

/// Parses a spelling; `what` names the setting in the error.
/// @throws InvalidArgumentError "<what>: is \"x\"; rule: must be one of [a, b, …]".
[[nodiscard]] inline ExplorationKind parse_exploration_kind(std::string_view text,
                                                            std::string_view what = "exploration") {
  return parse_name(exploration_kind_names, text, what);
}

}  // namespace twincal
