#include "twincal/controllers/additive_warm_start.hpp"

#include <gtest/gtest.h>

namespace twincal {
namespace {

TEST(AdditiveWarmStart, PhasesSplitTheFirstRowAndColumnFromTheRest) {
  EXPECT_EQ(AdditiveWarmStart::phase({0, 0}), 0);
  EXPECT_EQ(AdditiveWarmStart::phase({0, 4}), 0);
  EXPECT_EQ(AdditiveWarmStart::phase({3, 0}), 0);
  EXPECT_EQ(AdditiveWarmStart::phase({1, 1}), 1);
}

// For an affine twin u0(i, j) = −B⁺ (y_U(i) + y_L(j)) is additive in the parts, so the start is
// the optimum itself (inside the box).
TEST(AdditiveWarmStart, StartIsExactForOptimaAdditiveInTheParts) {
  const VectorX lower = VectorX::Constant(2, -1.0);
  const VectorX upper = VectorX::Constant(2, 1.0);
  AdditiveWarmStart warm(lower, upper);
  const auto u0 = [](Index i, Index j) {
    return VectorX(
        (Vector<2>() << 0.1 * double(i) - 0.2 * double(j), 0.05 * double(i * i) + 0.1).finished());
  };
  const VectorX centre = VectorX::Zero(2);
  EXPECT_EQ(warm.start({2, 3}, centre), centre);  // nothing recorded: the fallback
  for (Index i = 0; i < 4; ++i) warm.record({i, 0}, u0(i, 0));
  EXPECT_FALSE(warm.has_start({2, 3}));
  for (Index j = 1; j < 4; ++j) warm.record({0, j}, u0(0, j));
  for (Index i = 1; i < 4; ++i) {
    for (Index j = 1; j < 4; ++j) {
      ASSERT_TRUE(warm.has_start({i, j}));
      const VectorX expected = u0(i, j).cwiseMax(lower).cwiseMin(upper);
      EXPECT_TRUE(warm.start({i, j}, centre).isApprox(expected, 1e-15)) << i << "," << j;
    }
  }
  // Clipped to the box: (3, 3) sums to 0.3 − 0.6 = −0.3 and 0.55 inside; push one outside.
  warm.record({3, 0}, (Vector<2>() << 0.9, 0.9).finished());
  warm.record({0, 3}, (Vector<2>() << 0.9, -0.9).finished());
  EXPECT_TRUE(warm.start({3, 3}, centre).isApprox((Vector<2>() << 1.0, -0.1).finished(), 1e-15));
  EXPECT_FALSE(warm.has_start({0, 2}));  // phase 0 never has one
}

TEST(AdditiveWarmStart, RefusesBadBoxesAndOptima) {
  EXPECT_THROW(AdditiveWarmStart(VectorX::Constant(2, 1.0), VectorX::Constant(2, -1.0)),
               InvalidArgumentError);
  EXPECT_THROW(AdditiveWarmStart(VectorX::Zero(2), VectorX::Zero(3)), DimensionMismatchError);
  AdditiveWarmStart warm(VectorX::Constant(2, -1.0), VectorX::Constant(2, 1.0));
  EXPECT_THROW(warm.record({0, 0}, VectorX::Zero(3)), DimensionMismatchError);
  EXPECT_THROW(warm.record({0, 0}, VectorX::Constant(2, std::nan(""))), NonFiniteError);
}

}  // namespace
}  // namespace twincal
