#pragma once
/// @file
/// `strict_value<T>`: one JSON value of a config read as T, never coerced — an integer field
/// takes a JSON integer in T's range (2.9 is not 2, −5 is not 2⁶⁴ − 5, 1e30 is not a count);
/// anything else is an `InvalidArgumentError` naming the key, the value and the rule.

#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <type_traits>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "twincal/core/error.hpp"

namespace twincal {

/// @throws InvalidArgumentError unless `value` is a JSON integer within T's range.
template <typename T>
void require_json_integer(const nlohmann::json& value, std::string_view key) {
  const std::string shown = value.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  const auto refuse = [&](std::string_view rule) {
    throw InvalidArgumentError(std::string(key),
                               fmt::format("{}: is {}; rule: {}", key, shown, rule));
  };
  constexpr bool is_unsigned = std::is_unsigned_v<T>;
  if (!value.is_number_integer() || (is_unsigned && !value.is_number_unsigned())) {
    refuse(is_unsigned ? "a non-negative integer" : "an integer");
  }
  const bool fits =
      value.is_number_unsigned()
          ? value.get<std::uint64_t>() <= static_cast<std::uint64_t>(std::numeric_limits<T>::max())
          : value.get<std::int64_t>() >= static_cast<std::int64_t>(std::numeric_limits<T>::min());
  if (!fits) {
    refuse(fmt::format("an integer in [{}, {}]", std::numeric_limits<T>::min(),
                       std::numeric_limits<T>::max()));
  }
}

/// `value` as T: integers strictly (require_json_integer), everything else by nlohmann's
/// conversion with its error named.
/// @throws InvalidArgumentError naming `key`.
template <typename T>
T strict_value(const nlohmann::json& value, std::string_view key) {
  if constexpr (std::is_integral_v<T> && !std::is_same_v<T, bool>) {
    require_json_integer<T>(value, key);
  }
  try {
    return value.get<T>();
  } catch (const nlohmann::json::exception& error) {
    throw InvalidArgumentError(std::string(key),
                               fmt::format("{}: is {}; rule: {}", key, value.dump(), error.what()));
  }
}

}  // namespace twincal
