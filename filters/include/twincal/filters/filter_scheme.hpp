#pragma once
/// @file
/// `FilterScheme`: the sigma-point scheme of a filter chosen by name at run time (in configs,
/// on the command line, from Python), with its spellings. Each value names one scheme type of
/// this module; the caller instantiates the filter for it.

#include <array>
#include <string_view>

#include "twincal/core/name_table.hpp"

namespace twincal {

/// The sigma-point scheme of the filter (the paper's UKF is merwe).
enum class FilterScheme { merwe, julier, cubature, fifth_degree, simplex };

/// The spellings in configs and on the command line (name_table.hpp).
inline constexpr auto filter_scheme_names =
    std::to_array<NameEntry<FilterScheme>>({{FilterScheme::merwe, "merwe"},
                                            {FilterScheme::julier, "julier"},
                                            {FilterScheme::cubature, "cubature"},
                                            {FilterScheme::fifth_degree, "fifth_degree"},
                                            {FilterScheme::simplex, "simplex"}});

[[nodiscard]] constexpr std::string_view to_string(FilterScheme value) noexcept {
  return name_of(filter_scheme_names, value);
}

/// Parses a spelling; `what` names the setting in the error.
/// @throws InvalidArgumentError "<what>: is \"x\"; rule: must be one of [a, b, …]".
[[nodiscard]] inline FilterScheme parse_filter_scheme(std::string_view text,
                                                      std::string_view what = "filter") {
  return parse_name(filter_scheme_names, text, what);
}

}  // namespace twincal
