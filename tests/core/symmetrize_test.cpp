#include "twincal/core/symmetrize.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace twincal {
namespace {

TEST(Symmetrize, AveragesOffDiagonalPairsInPlace) {
  Eigen::Matrix3d m;
  m << 1, 2, 3, 4, 5, 6, 7, 8, 9;
  symmetrize(m);
  Eigen::Matrix3d expected;
  expected << 1, 3, 5, 3, 5, 7, 5, 7, 9;
  EXPECT_EQ(m, expected);
}

TEST(Symmetrize, WorksOnBlocksAndDynamicMatrices) {
  Eigen::MatrixXd m = Eigen::MatrixXd::Zero(4, 4);
  m(2, 1) = 2.0;
  Eigen::Block<Eigen::MatrixXd> block = m.bottomRightCorner(3, 3);
  symmetrize(block);
  EXPECT_EQ(m(1, 2), 1.0);
  EXPECT_EQ(m(2, 1), 1.0);
  EXPECT_EQ(symmetrized(Eigen::Matrix2d(Eigen::Matrix2d::Identity())), Eigen::Matrix2d::Identity());
}

TEST(Symmetrize, RejectsNonSquare) {
  Eigen::MatrixXd m = Eigen::MatrixXd::Zero(2, 3);
  EXPECT_THAT([&] { symmetrize(m); },
              ::testing::ThrowsMessage<DimensionMismatchError>("m: is 2x3; rule: must be square"));
}

}  // namespace
}  // namespace twincal
