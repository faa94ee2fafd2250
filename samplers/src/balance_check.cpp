#include "twincal/samplers/balance_check.hpp"

#include <cstdio>

#include <fmt/format.h>

#include "twincal/core/error.hpp"

namespace twincal {

void check_balance(BalanceCheck check, const WarningHandler& handler, std::string_view argument,
                   std::string_view sampler_name, std::uint64_t start, std::uint64_t count) {
  if (check == BalanceCheck::ignore || is_balanced_block(start, count)) return;
  const std::string message = fmt::format(
      "{}: {} asks for {} points starting at point {}; rule: the power-of-two balance property "
      "needs a power-of-two count starting at a multiple of it",
      argument, sampler_name, count, start);
  if (check == BalanceCheck::refuse) throw InvalidArgumentError(std::string(argument), message);
  if (handler) {
    handler(message);
  } else {
    fmt::print(stderr, "twincal warning: {}\n", message);
  }
}

}  // namespace twincal
