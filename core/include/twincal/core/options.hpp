#pragma once
/// @file
/// Options are aggregates with defaults and a `validate()` that returns nothing when they are
/// consistent and otherwise one sentence saying which field broke which rule (Ceres style).
/// Classes taking options call `require_valid` in their constructor.

#include <concepts>
#include <optional>
#include <string>
#include <string_view>

#include <fmt/format.h>

#include "twincal/core/error.hpp"

namespace twincal {

/// An options aggregate: `validate()` returns std::nullopt or a sentence naming the problem.
template <typename T>
concept ValidatableOptions = requires(const T& options) {
  { options.validate() } -> std::same_as<std::optional<std::string>>;
};

/// Throws InvalidArgumentError("<name>: <sentence>") when `options.validate()` reports a problem.
template <ValidatableOptions Options>
void require_valid(std::string_view name, const Options& options) {
  if (std::optional<std::string> problem = options.validate()) {
    throw InvalidArgumentError(std::string(name), fmt::format("{}: {}", name, *problem));
  }
}

}  // namespace twincal
