#pragma once
/// @file
/// `FilterScheme`: the sigma-point scheme of a filter chosen by name at run time (in configs,
/// on the command line, from Python), with its spellings. Each value names one scheme type of
/// this module; the caller instantiates the filter for it.

#include <array>
#include <string_view>
#include <type_traits>

#include "twincal/core/named_enum.hpp"

namespace twincal {

/// The sigma-point scheme of the filter (the paper's UKF is merwe).
enum class FilterScheme { merwe, julier, cubature, fifth_degree, simplex };

/// The spellings in configs and on the command line, for to_string and parse_enum
/// (named_enum.hpp).
[[nodiscard]] constexpr auto name_table(std::type_identity<FilterScheme>) noexcept {
  return std::to_array<NameEntry<FilterScheme>>({{FilterScheme::merwe, "merwe"},
                                                 {FilterScheme::julier, "julier"},
                                                 {FilterScheme::cubature, "cubature"},
                                                 {FilterScheme::fifth_degree, "fifth_degree"},
                                                 {FilterScheme::simplex, "simplex"}});
}

}  // namespace twincal
