#include "twincal/core/format.hpp"

#include <fmt/ranges.h>
#include <gtest/gtest.h>

#include "twincal/core/eigen.hpp"

namespace twincal {
namespace {

TEST(Format, VectorsPrintAsOneList) {
  EXPECT_EQ(fmt::format("{}", Eigen::Vector3d(1.0, 2.5, -3.0)), "[1, 2.5, -3]");
  EXPECT_EQ(fmt::format("{}", Eigen::RowVector2d(4.0, 5.0)), "[4, 5]");
  EXPECT_EQ(fmt::format("{}", Eigen::VectorXd()), "[]");
}

TEST(Format, MatricesPrintRowByRow) {
  Eigen::Matrix<double, 2, 3> m;
  m << 1, 2, 3, 4, 5, 6;
  EXPECT_EQ(fmt::format("{}", m), "[[1, 2, 3], [4, 5, 6]]");
}

TEST(Format, SpecAppliesToEveryElement) {
  EXPECT_EQ(fmt::format("{:.2f}", Eigen::Vector2d(1.0, 1.0 / 3.0)), "[1.00, 0.33]");
  EXPECT_EQ(fmt::format("{:>5}", Eigen::Vector2d(1.0, 2.0)), "[    1,     2]");
}

TEST(Format, ExpressionsAreEvaluated) {
  const Eigen::Vector2d a(1.0, 2.0);
  const Eigen::Vector2d b(0.5, 0.5);
  EXPECT_EQ(fmt::format("{}", a - b), "[0.5, 1.5]");
  EXPECT_EQ(fmt::format("{}", a.transpose()), "[1, 2]");
  EXPECT_EQ(fmt::format("{}", a * b.transpose()), "[[0.5, 0.5], [1, 1]]");
}

TEST(Format, IntegerMatrices) { EXPECT_EQ(fmt::format("{}", Eigen::Vector2i(3, 4)), "[3, 4]"); }

}  // namespace
}  // namespace twincal
