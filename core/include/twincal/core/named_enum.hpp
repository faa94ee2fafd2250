#pragma once
/// @file
/// An enum chosen by name at run time (in configs, on the command line, from Python) declares
/// its spellings once, as a `name_table` function beside the enum (found by argument-dependent
/// lookup); one `to_string` and one `parse_enum` then serve every such enum, so that printing
/// and parsing cannot disagree and a new value is one new row:
///
///     [[nodiscard]] constexpr auto name_table(std::type_identity<CovarianceRepair>) noexcept {
///       return std::to_array<NameEntry<CovarianceRepair>>(
///           {{CovarianceRepair::none, "none"}, {CovarianceRepair::jitter, "jitter"}});
///     }
///
///     to_string(CovarianceRepair::jitter)                 // "jitter"
///     parse_enum<CovarianceRepair>("jitter", "--repair")  // CovarianceRepair::jitter
///
/// `parse_enum` refuses a spelling in the format of every twincal error, listing the choices:
/// `<what>: is "x"; rule: must be one of [a, b, …]`.

#include <concepts>
#include <string_view>
#include <type_traits>

#include "twincal/core/name_table.hpp"

namespace twincal {

/// An enum with a name table: `name_table(std::type_identity<Enum>{})` returns the
/// NameTable<Enum, N> (name_table.hpp) of its spellings, in the order they are listed to users.
template <typename Enum>
concept NamedEnum = std::is_enum_v<Enum> && requires(Enum value) {
  { name_of(name_table(std::type_identity<Enum>{}), value) } -> std::same_as<std::string_view>;
};

/// The spelling of `value`; "unknown" for a value the table does not list (a cast integer).
template <NamedEnum Enum>
[[nodiscard]] constexpr std::string_view to_string(Enum value) noexcept {
  return name_of(name_table(std::type_identity<Enum>{}), value);
}

/// The value spelled `text`; `what` names the setting in the error.
/// @throws InvalidArgumentError "<what>: is \"x\"; rule: must be one of [a, b, …]", naming
///         `what`.
template <NamedEnum Enum>
[[nodiscard]] Enum parse_enum(std::string_view text, std::string_view what) {
  return parse_name(name_table(std::type_identity<Enum>{}), text, what);
}

}  // namespace twincal
