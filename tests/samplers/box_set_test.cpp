#include "twincal/samplers/box_set.hpp"

#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "twincal/core/error.hpp"

namespace twincal {
namespace {

template <typename T>
class BoxSetTest : public ::testing::Test {
 public:
  static constexpr int N = T::value;
  static Vector<N> vector(double a, double b) {
    Vector<N> v(2);
    v << a, b;
    return v;
  }
};

using Sizes =
    ::testing::Types<std::integral_constant<int, 2>, std::integral_constant<int, Dynamic>>;
TYPED_TEST_SUITE(BoxSetTest, Sizes);

TYPED_TEST(BoxSetTest, ContainsIsInclusiveAndRejectsNan) {
  const auto box = BoxSet<TestFixture::N>::cube(TestFixture::vector(1.0, -1.0), 0.5);
  EXPECT_TRUE(box.contains(TestFixture::vector(1.0, -1.0)));
  EXPECT_TRUE(box.contains(TestFixture::vector(1.5, -1.5)));  // on the boundary
  EXPECT_FALSE(box.contains(TestFixture::vector(1.5000001, -1.0)));
  EXPECT_FALSE(box.contains(TestFixture::vector(1.0, std::numeric_limits<double>::quiet_NaN())));
}

TYPED_TEST(BoxSetTest, KeepInsideCompactsSurvivorsInOrder) {
  const BoxSet<TestFixture::N> box(TestFixture::vector(0.0, 0.0), TestFixture::vector(1.0, 2.0));
  Matrix<TestFixture::N, Dynamic> points(2, 5);
  points << 0.5, 3.0, -1.0, 0.0, 0.9,  //
      1.9, 0.0, -2.0, 2.5, -0.1;
  const Index kept = box.keep_inside(points);
  ASSERT_EQ(kept, 3);
  Matrix<TestFixture::N, Dynamic> expected(2, 3);
  expected << 0.5, -1.0, 0.9,  //
      1.9, -2.0, -0.1;
  EXPECT_EQ(points.leftCols(3), expected);
}

TYPED_TEST(BoxSetTest, RejectsBadArguments) {
  try {
    const BoxSet<TestFixture::N> box(TestFixture::vector(0.0, 0.0), TestFixture::vector(0.1, -0.2));
    FAIL();
  } catch (const InvalidArgumentError& e) {
    EXPECT_EQ(std::string(e.what()), "half_width(1): value is -0.2; rule: must be >= 0");
  }
  EXPECT_THROW((void)BoxSet<TestFixture::N>::cube(
                   TestFixture::vector(std::numeric_limits<double>::infinity(), 0.0), 0.1),
               NonFiniteError);
}

TEST(BoxSet, RejectsMismatchedSizes) {
  EXPECT_THROW(BoxSet<Dynamic>(VectorX::Zero(3), VectorX::Ones(2)), DimensionMismatchError);
  const auto box = BoxSet<Dynamic>::cube(VectorX::Zero(3), 0.1);
  MatrixX points(2, 4);
  EXPECT_THROW((void)box.keep_inside(points), DimensionMismatchError);
  EXPECT_THROW((void)box.contains(VectorX::Zero(2)), DimensionMismatchError);
}

}  // namespace
}  // namespace twincal
