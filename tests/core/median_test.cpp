#include "twincal/core/median.hpp"

#include <array>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "twincal/core/error.hpp"

namespace twincal {
namespace {

TEST(MedianOfFirst, IsTheMiddleOfAnOddCountAndTheUpperMiddleOfAnEvenOne) {
  const std::array<double, 5> values{4.0, -1.0, 9.0, 2.0, 7.0};
  std::array<double, 5> workspace{};
  EXPECT_EQ(median_of_first(values, 5, workspace), 4.0);  // -1 2 [4] 7 9
  EXPECT_EQ(median_of_first(values, 4, workspace), 4.0);  // -1 2 [4] 9
  EXPECT_EQ(median_of_first(values, 2, workspace), 4.0);  // -1 [4]
  EXPECT_EQ(median_of_first(values, 1, workspace), 4.0);
  EXPECT_EQ(median_of_first(values, 3, workspace), 4.0);  // -1 [4] 9
  const std::array<double, 3> rising{1.0, 2.0, 3.0};
  EXPECT_EQ(median_of_first(rising, 2, workspace), 2.0);
}

TEST(MedianOfFirst, LeavesItsValuesAsTheyWere) {
  const std::vector<double> values{3.0, 1.0, 2.0};
  std::vector<double> workspace(3);
  EXPECT_EQ(median_of_first(values, 3, workspace), 2.0);
  EXPECT_THAT(values, ::testing::ElementsAre(3.0, 1.0, 2.0));
}

TEST(MedianOfFirst, NamesACountOutsideItsValuesOrWorkspace) {
  const std::array<double, 3> values{1.0, 2.0, 3.0};
  std::array<double, 2> workspace{};
  EXPECT_THAT([&] { (void)median_of_first(values, 0, workspace); },
              ::testing::ThrowsMessage<InvalidArgumentError>(
                  ::testing::StrEq("count: value is 0; rule: must lie in [1, 2]")));
  EXPECT_THROW((void)median_of_first(values, 3, workspace), InvalidArgumentError);
}

}  // namespace
}  // namespace twincal
