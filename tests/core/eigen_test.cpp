#include "twincal/core/eigen.hpp"

#include <type_traits>

#include <gtest/gtest.h>

namespace twincal {
namespace {

static_assert(std::is_same_v<Vector<3>, Eigen::Vector3d>);
static_assert(std::is_same_v<Vector<Dynamic>, Eigen::VectorXd>);
static_assert(std::is_same_v<Matrix<2, Dynamic>, Eigen::Matrix<double, 2, Eigen::Dynamic>>);
static_assert(std::is_same_v<SquareMatrix<4>, Eigen::Matrix4d>);
static_assert(std::is_same_v<RowVector<2>, Eigen::RowVector2d>);
static_assert(size_sum(3, 4) == 7);
static_assert(size_sum(Dynamic, 4) == Dynamic);
static_assert(size_sum(3, Dynamic) == Dynamic);
static_assert(size_product(2, 3) == 6);
static_assert(size_product(2, Dynamic) == Dynamic);

TEST(EigenAliases, DynamicVectorsResizeAtRunTime) {
  VectorX v(5);
  EXPECT_EQ(v.size(), 5);
  Matrix<3, Dynamic> m(3, 7);
  EXPECT_EQ(m.cols(), 7);
}

}  // namespace
}  // namespace twincal
