#include "twincal/samplers/balance_check.hpp"

#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "twincal/core/error.hpp"

namespace twincal {
namespace {

TEST(BalanceCheck, AlignedPowerOfTwoBlocksAreBalanced) {
  EXPECT_TRUE(is_balanced_block(0, 1));
  EXPECT_TRUE(is_balanced_block(5, 1));
  EXPECT_TRUE(is_balanced_block(0, 64));
  EXPECT_TRUE(is_balanced_block(128, 64));
  EXPECT_TRUE(is_balanced_block(std::uint64_t{1} << 40, std::uint64_t{1} << 40));
  EXPECT_FALSE(is_balanced_block(0, 0));
  EXPECT_FALSE(is_balanced_block(0, 48));
  EXPECT_FALSE(is_balanced_block(1, 64));   // the first point dropped
  EXPECT_FALSE(is_balanced_block(32, 64));  // a power of two, misaligned
}

TEST(BalanceCheck, WarnsRefusesOrIgnores) {
  std::vector<std::string> messages;
  const WarningHandler handler = [&](const std::string& m) { messages.push_back(m); };
  check_balance(BalanceCheck::warn, handler, "points", "Sobol fill", 64, 64);
  EXPECT_TRUE(messages.empty());
  check_balance(BalanceCheck::ignore, handler, "points", "Sobol fill", 3, 5);
  EXPECT_TRUE(messages.empty());
  check_balance(BalanceCheck::warn, handler, "count", "Sobol discard", 0, 3);
  ASSERT_EQ(messages.size(), 1U);
  EXPECT_EQ(messages[0],
            "count: Sobol discard asks for 3 points starting at point 0; rule: the power-of-two "
            "balance property needs a power-of-two count starting at a multiple of it");
  try {
    check_balance(BalanceCheck::refuse, handler, "points", "Sobol fill", 1, 64);
    FAIL();
  } catch (const InvalidArgumentError& e) {
    EXPECT_EQ(e.argument(), "points");
    EXPECT_EQ(std::string(e.what()),
              "points: Sobol fill asks for 64 points starting at point 1; rule: the power-of-two "
              "balance property needs a power-of-two count starting at a multiple of it");
  }
  EXPECT_EQ(messages.size(), 1U);
  EXPECT_EQ(to_string(BalanceCheck::refuse), "refuse");
}

}  // namespace
}  // namespace twincal
