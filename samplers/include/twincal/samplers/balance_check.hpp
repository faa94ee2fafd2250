#pragma once
/// @file
/// The power-of-two balance property of digital (t, m, s)-nets in base 2 (Sobol): the points
/// with indices k·2^m … (k+1)·2^m − 1 form a net, so every coordinate is exactly stratified
/// into 2^m cells and scrambled estimates keep their fast variance decay. A batch of any other
/// size or alignment (e.g. after dropping the first point) loses it. `BalanceCheck` says what a
/// sampler does with such a request.

#include <cstdint>
#include <functional>
#include <string>
#include <string_view>

namespace twincal {

/// What to do with a request that breaks the power-of-two balance property.
enum class BalanceCheck {
  ignore,  ///< generate silently
  warn,    ///< generate, and report through the warning handler (default: standard error)
  refuse,  ///< throw InvalidArgumentError before any state changes
};

[[nodiscard]] constexpr std::string_view to_string(BalanceCheck check) noexcept {
  switch (check) {
    case BalanceCheck::ignore:
      return "ignore";
    case BalanceCheck::warn:
      return "warn";
    case BalanceCheck::refuse:
      return "refuse";
  }
  return "unknown";
}

/// Receives warnings (one sentence each); an empty handler writes to standard error.
using WarningHandler = std::function<void(const std::string&)>;

/// True when points start … start + count − 1 form an aligned block of 2^m points (count a
/// power of two, start a multiple of count), i.e. a (t, m, s)-net of a base-2 sequence.
[[nodiscard]] constexpr bool is_balanced_block(std::uint64_t start, std::uint64_t count) noexcept {
  return count != 0 && (count & (count - 1)) == 0 && start % count == 0;
}

/// Applies `check` to a request for points start … start + count − 1 of `sampler_name`
/// (argument `argument` of the call): nothing when balanced or ignored; otherwise warns through
/// `handler` or throws InvalidArgumentError naming `argument`, the request and the rule.
void check_balance(BalanceCheck check, const WarningHandler& handler, std::string_view argument,
                   std::string_view sampler_name, std::uint64_t start, std::uint64_t count);

}  // namespace twincal
