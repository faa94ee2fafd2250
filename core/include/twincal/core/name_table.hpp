#pragma once
/// @file
/// The spellings of an enum's values, as one constexpr table, read in both directions by
/// `name_of` and `parse_name`. An enum declares its table through `name_table` and gets
/// `to_string` and `parse_enum` from named_enum.hpp.
///
/// `parse_name` refuses a spelling in the format of every twincal error, listing the choices:
/// `<what>: is "x"; rule: must be one of [a, b, …]`.

#include <array>
#include <cstddef>
#include <string>
#include <string_view>

#include <fmt/format.h>

#include "twincal/core/error.hpp"

namespace twincal {

/// One row of a name table: a value and its spelling.
template <typename Enum>
struct NameEntry {
  Enum value;
  std::string_view name;
};

/// The spellings of `Enum`'s values, in the order they are listed to the user.
template <typename Enum, std::size_t Size>
using NameTable = std::array<NameEntry<Enum>, Size>;

/// The spelling of `value`; "unknown" for a value the table does not list (a cast integer).
template <typename Enum, std::size_t Size>
[[nodiscard]] constexpr std::string_view name_of(const NameTable<Enum, Size>& table,
                                                 Enum value) noexcept {
  for (const NameEntry<Enum>& entry : table) {
    if (entry.value == value) return entry.name;
  }
  return "unknown";
}

/// The value spelled `text`; `what` names the setting in the error.
/// @throws InvalidArgumentError "<what>: is \"x\"; rule: must be one of [a, b, …]", naming
///         `what`.
template <typename Enum, std::size_t Size>
[[nodiscard]] Enum parse_name(const NameTable<Enum, Size>& table, std::string_view text,
                              std::string_view what) {
  std::array<std::string_view, Size> names{};
  for (std::size_t i = 0; i < Size; ++i) {
    if (table[i].name == text) return table[i].value;
    names[i] = table[i].name;
  }
  throw InvalidArgumentError(
      std::string(what),
      fmt::format("{}: is \"{}\"; rule: must be one of [{}]", what, text, fmt::join(names, ", ")));
}

}  // namespace twincal
