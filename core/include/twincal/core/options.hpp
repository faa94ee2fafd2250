#pragma once
/// @file
/// Options are aggregates with defaults and a `validate()` that returns nothing when they are
/// consistent and otherwise one sentence saying which field broke which rule (Ceres style).
/// Classes taking options call `require_valid` in their constructor.
///
/// A validate() body is a list of rules, one line each, in one message format:
///
///     return first_problem({rule::positive_finite("step", step),
///                           rule::in_closed("w", w, 0.0, 1.0),
///                           rule::at_least("count", count, Index{1})});
///
/// Each rule returns nothing when it holds, otherwise "<field>: value is <v>; rule: <rule>". A
/// rule that relates several fields, or that no helper states, is written out in the same
/// format ("<fields>: values are …; rule: …"). A nested aggregate's problem is named by its path
/// (`rule::nested("section", section)` → "section.thickness: value is …").

#include <array>
#include <cmath>
#include <concepts>
#include <cstddef>
#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "twincal/core/error.hpp"

namespace twincal {

/// An options aggregate: `validate()` returns std::nullopt or a sentence naming the problem.
template <typename T>
concept ValidatableOptions = requires(const T& options) {
  { options.validate() } -> std::same_as<std::optional<std::string>>;
};

/// The first problem among `rules`, in their order; nothing when every rule holds.
[[nodiscard]] inline std::optional<std::string> first_problem(
    std::initializer_list<std::optional<std::string>> rules) {
  for (const std::optional<std::string>& problem : rules) {
    if (problem) return problem;
  }
  return std::nullopt;
}

/// The rules of option fields, in one message format (see the file comment). NaN breaks every
/// rule on doubles.
namespace rule {

/// "<field>: value is <value>; rule: <rule formatted with args>" unless `holds`. The sentence
/// is formatted only for a broken rule, so a validate() that passes allocates nothing: cholesky()
/// and CandidateSet::draw() validate their options on every call, inside controllers' loops.
template <typename T, typename... Args>
[[nodiscard]] std::optional<std::string> check(bool holds, std::string_view field, T&& value,
                                               fmt::format_string<Args...> rule, Args&&... args) {
  if (holds) return std::nullopt;
  // Forwarded: fmt takes a view (fmt::join of several fields) only as an rvalue.
  return fmt::format("{}: value is {}; rule: {}", field, std::forward<T>(value),
                     fmt::format(rule, std::forward<Args>(args)...));
}

/// "<fields>: values are <v1> and <v2>…; rule: <rule formatted with args>" unless `holds`: a rule
/// that relates several fields.
template <typename T, std::size_t N, typename... Args>
[[nodiscard]] std::optional<std::string> check_fields(bool holds, std::string_view fields,
                                                      const std::array<T, N>& values,
                                                      fmt::format_string<Args...> rule,
                                                      Args&&... args) {
  if (holds) return std::nullopt;
  return fmt::format("{}: values are {}; rule: {}", fields, fmt::join(values, " and "),
                     fmt::format(rule, std::forward<Args>(args)...));
}

/// value finite and > 0.
[[nodiscard]] inline std::optional<std::string> positive_finite(std::string_view field,
                                                                double value) {
  return check(std::isfinite(value) && value > 0.0, field, value, "must be finite and > 0");
}

/// value finite and >= 0.
[[nodiscard]] inline std::optional<std::string> non_negative_finite(std::string_view field,
                                                                    double value) {
  return check(std::isfinite(value) && value >= 0.0, field, value, "must be finite and >= 0");
}

/// value finite and > bound.
[[nodiscard]] inline std::optional<std::string> finite_above(std::string_view field, double value,
                                                             double bound) {
  return check(std::isfinite(value) && value > bound, field, value, "must be finite and > {}",
               bound);
}

/// value finite and >= bound.
[[nodiscard]] inline std::optional<std::string> finite_at_least(std::string_view field,
                                                                double value, double bound) {
  return check(std::isfinite(value) && value >= bound, field, value, "must be finite and >= {}",
               bound);
}

/// lo <= value <= hi.
[[nodiscard]] inline std::optional<std::string> in_closed(std::string_view field, double value,
                                                          double lo, double hi) {
  return check(value >= lo && value <= hi, field, value, "must lie in [{}, {}]", lo, hi);
}

/// lo < value <= hi.
[[nodiscard]] inline std::optional<std::string> in_left_open(std::string_view field, double value,
                                                             double lo, double hi) {
  return check(value > lo && value <= hi, field, value, "must lie in ({}, {}]", lo, hi);
}

/// lo <= value < hi.
[[nodiscard]] inline std::optional<std::string> in_right_open(std::string_view field, double value,
                                                              double lo, double hi) {
  return check(value >= lo && value < hi, field, value, "must lie in [{}, {})", lo, hi);
}

/// lo < value < hi.
[[nodiscard]] inline std::optional<std::string> in_open(std::string_view field, double value,
                                                        double lo, double hi) {
  return check(value > lo && value < hi, field, value, "must lie in ({}, {})", lo, hi);
}

/// Two fields that bound a range: 0 < low <= high < inf.
[[nodiscard]] inline std::optional<std::string> positive_range(std::string_view low_field,
                                                               double low,
                                                               std::string_view high_field,
                                                               double high) {
  if (low > 0.0 && high >= low && std::isfinite(high)) return std::nullopt;
  return check_fields(false, fmt::format("{} and {}", low_field, high_field), std::array{low, high},
                      "0 < {} <= {} < inf", low_field, high_field);
}

/// An integer value >= least.
template <std::integral I>
[[nodiscard]] std::optional<std::string> at_least(std::string_view field, I value, I least) {
  return check(value >= least, field, value, "must be >= {}", least);
}

/// The problem of a nested options aggregate, named by its path: "<field>.<its problem>".
template <ValidatableOptions Options>
[[nodiscard]] std::optional<std::string> nested(std::string_view field, const Options& options) {
  std::optional<std::string> problem = options.validate();
  if (problem) problem->insert(0, fmt::format("{}.", field));
  return problem;
}

}  // namespace rule

/// Throws InvalidArgumentError("<name>: <sentence>") when `options.validate()` reports a problem.
template <ValidatableOptions Options>
void require_valid(std::string_view name, const Options& options) {
  if (std::optional<std::string> problem = options.validate()) {
    throw InvalidArgumentError(std::string(name), fmt::format("{}: {}", name, *problem));
  }
}

}  // namespace twincal
