#include "twincal/models/drift.hpp"

#include <limits>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "twincal/core/random_stream.hpp"
#include "twincal/models/bouncing_drift.hpp"
#include "twincal/models/brownian_drift.hpp"
#include "twincal/models/constant_drift.hpp"
#include "twincal/models/step_drift.hpp"

namespace twincal {
namespace {

template <typename Size>
class DriftTest : public ::testing::Test {
 protected:
  static constexpr int N = Size::value;
  using Offset = Vector<N>;
  static Offset vec(double a, double b) {
    Offset v(2);
    v << a, b;
    return v;
  }
};

using Sizes =
    ::testing::Types<std::integral_constant<int, 2>, std::integral_constant<int, Dynamic>>;
TYPED_TEST_SUITE(DriftTest, Sizes);

TYPED_TEST(DriftTest, ScenariosSatisfyTheDriftConcept) {
  static_assert(Drift<BouncingDrift<TestFixture::N>>);
  static_assert(Drift<BrownianDrift<TestFixture::N>>);
  static_assert(Drift<StepDrift<TestFixture::N>>);
  static_assert(Drift<ConstantDrift<TestFixture::N>>);
}

TYPED_TEST(DriftTest, BouncingDriftReproducesEquation15StepByStep) {
  // p_0 = (0.03, −0.02), b = (0.1, 0.05), δu*_0 = 0. By hand, with eq. (15):
  //  t  δu*_t           check |δu*_t| ≤ b      p_t
  //  1  ( 0.03, −0.02)  ok                     ( 0.03, −0.02)
  //  2  ( 0.06, −0.04)  ok                     ( 0.03, −0.02)
  //  3  ( 0.09, −0.06)  0.06 > 0.05: reverse   (−0.03,  0.02)
  //  4  ( 0.06, −0.04)  ok                     (−0.03,  0.02)
  //  5  ( 0.03, −0.02)  ok
  //  6  ( 0.00,  0.00)  ok
  //  7  (−0.03,  0.02)  ok
  //  8  (−0.06,  0.04)  ok
  //  9  (−0.09,  0.06)  0.06 > 0.05: reverse   ( 0.03, −0.02)
  // 10  (−0.06,  0.04)  ok                     ( 0.03, −0.02)
  using Pair = std::pair<typename TestFixture::Offset, typename TestFixture::Offset>;
  BouncingDrift<TestFixture::N> drift(this->vec(0.03, -0.02), this->vec(0.1, 0.05));
  const std::vector<Pair> expected = {
      {this->vec(0.03, -0.02), this->vec(0.03, -0.02)},
      {this->vec(0.06, -0.04), this->vec(0.03, -0.02)},
      {this->vec(0.09, -0.06), this->vec(-0.03, 0.02)},
      {this->vec(0.06, -0.04), this->vec(-0.03, 0.02)},
      {this->vec(0.03, -0.02), this->vec(-0.03, 0.02)},
      {this->vec(0.00, 0.00), this->vec(-0.03, 0.02)},
      {this->vec(-0.03, 0.02), this->vec(-0.03, 0.02)},
      {this->vec(-0.06, 0.04), this->vec(-0.03, 0.02)},
      {this->vec(-0.09, 0.06), this->vec(0.03, -0.02)},
      {this->vec(-0.06, 0.04), this->vec(0.03, -0.02)},
  };
  EXPECT_EQ(drift.time(), 0);
  EXPECT_EQ(drift.offset(), TestFixture::Offset::Zero(2));
  for (std::size_t t = 0; t < expected.size(); ++t) {
    drift.advance();
    EXPECT_EQ(drift.time(), static_cast<Index>(t + 1));
    EXPECT_TRUE(drift.offset().isApprox(expected[t].first, 1e-14) ||
                (expected[t].first.isZero(0.0) && drift.offset().isZero(1e-15)))
        << "t = " << t + 1 << ": " << drift.offset().transpose();
    EXPECT_EQ(drift.step(), expected[t].second) << "t = " << t + 1;
  }
}

TYPED_TEST(DriftTest, PaperBouncingDriftIsSeededWithStepLengthAndBound) {
  RandomStream a(42);
  RandomStream b(42);
  RandomStream c(43);
  BouncingDrift<TestFixture::N> drift = BouncingDrift<TestFixture::N>::random(2, a);
  const BouncingDrift<TestFixture::N> same = BouncingDrift<TestFixture::N>::random(2, b);
  const BouncingDrift<TestFixture::N> other = BouncingDrift<TestFixture::N>::random(2, c);
  EXPECT_EQ(drift.step(), same.step());
  EXPECT_NE(drift.step(), other.step());
  EXPECT_NEAR(drift.step().norm(), 0.03, 1e-15);
  EXPECT_EQ(drift.bound(), TestFixture::Offset::Constant(2, 0.5));
  // The offset never leaves the box by a full step, and it does reach the bound and turn back.
  bool reversed = false;
  for (int t = 0; t < 1000; ++t) {
    const typename TestFixture::Offset before = drift.step();
    drift.advance();
    reversed = reversed || drift.step() != before;
    EXPECT_LE(drift.offset().cwiseAbs().maxCoeff(), 0.5 + 0.03);
  }
  EXPECT_TRUE(reversed);
}

TYPED_TEST(DriftTest, BrownianDriftHasTheIncrementCovarianceOfEquation5c) {
  typename BrownianDrift<TestFixture::N>::CovarianceMatrix sigma(2, 2);
  sigma << 1e-3, 4e-4, 4e-4, 2e-3;
  BrownianDrift<TestFixture::N> drift(this->vec(0.1, -0.1), sigma, RandomStream(5));
  EXPECT_TRUE((drift.square_root() * drift.square_root()).isApprox(sigma, 1e-12));
  constexpr int kSteps = 20000;
  Matrix<2, Dynamic> increments(2, kSteps);
  for (int t = 0; t < kSteps; ++t) {
    const typename TestFixture::Offset before = drift.offset();
    drift.advance();
    increments.col(t) = drift.offset() - before;
  }
  EXPECT_EQ(drift.time(), kSteps);
  const Eigen::Matrix2d empirical = increments * increments.transpose() / kSteps;
  // Standard error of each entry is below sqrt(2/n)·max σ² ≈ 2e-5; allow five of them.
  EXPECT_LT((empirical - Eigen::Matrix2d(sigma)).cwiseAbs().maxCoeff(), 1e-4);
  // Seeded: the same stream gives the same path.
  BrownianDrift<TestFixture::N> again(this->vec(0.1, -0.1), sigma, RandomStream(5));
  BrownianDrift<TestFixture::N> replay(this->vec(0.1, -0.1), sigma, RandomStream(5));
  for (int t = 0; t < 10; ++t) {
    again.advance();
    replay.advance();
  }
  EXPECT_EQ(again.offset(), replay.offset());
}

TYPED_TEST(DriftTest, BrownianDriftAcceptsASemiDefiniteCovariance) {
  typename BrownianDrift<TestFixture::N>::CovarianceMatrix sigma(2, 2);
  sigma << 1e-3, 0.0, 0.0, 0.0;  // the second locator does not drift
  BrownianDrift<TestFixture::N> drift(this->vec(0.0, 0.25), sigma, RandomStream(6));
  for (int t = 0; t < 100; ++t) drift.advance();
  EXPECT_EQ(drift.offset()(1), 0.25);
  EXPECT_NE(drift.offset()(0), 0.0);
  sigma(1, 1) = -1e-3;
  EXPECT_THROW((BrownianDrift<TestFixture::N>(this->vec(0.0, 0.0), sigma, RandomStream(6))),
               NotPositiveDefiniteError);
}

TYPED_TEST(DriftTest, StepAndConstantDrifts) {
  StepDrift<TestFixture::N> step(this->vec(0.0, 0.0), this->vec(0.2, -0.1), 3);
  ConstantDrift<TestFixture::N> constant(this->vec(0.05, 0.01));
  for (Index t = 0; t < 6; ++t) {
    EXPECT_EQ(step.offset(), t < 3 ? this->vec(0.0, 0.0) : this->vec(0.2, -0.1)) << "t = " << t;
    EXPECT_EQ(constant.offset(), this->vec(0.05, 0.01));
    EXPECT_EQ(step.time(), t);
    step.advance();
    constant.advance();
  }
}

TYPED_TEST(DriftTest, RejectsBadArguments) {
  EXPECT_THAT(
      [this] { (void)BouncingDrift<TestFixture::N>(this->vec(0.03, 0.0), this->vec(0.5, -0.1)); },
      ::testing::ThrowsMessage<InvalidArgumentError>("bound: entry 1 is -0.1; rule: must be >= 0"));
  EXPECT_THAT(
      [this] {
        (void)BouncingDrift<TestFixture::N>(this->vec(std::nan(""), 0.0), this->vec(0.5, 0.5));
      },
      ::testing::ThrowsMessage<NonFiniteError>(
          "step: entry 0 is nan; rule: every entry must be finite"));
  RandomStream stream(1);
  EXPECT_THAT(
      [&] { (void)BouncingDrift<TestFixture::N>::random(2, stream, 0.0); },
      ::testing::ThrowsMessage<InvalidArgumentError>("step_length: value is 0; rule: must be > 0"));
  EXPECT_THAT(
      [this] { (void)StepDrift<TestFixture::N>(this->vec(0.0, 0.0), this->vec(0.0, 0.0), -1); },
      ::testing::ThrowsMessage<InvalidArgumentError>("step_time: value is -1; rule: must be >= 0"));
  EXPECT_THROW(
      (void)ConstantDrift<TestFixture::N>(this->vec(std::numeric_limits<double>::infinity(), 0.0)),
      NonFiniteError);
}

TEST(BouncingDrift, DynamicDimensionsMustAgree) {
  EXPECT_THAT(
      [] { (void)BouncingDrift<Dynamic>(VectorX::Zero(3), VectorX::Ones(2)); },
      ::testing::ThrowsMessage<DimensionMismatchError>("bound: size is 2; rule: must equal 3"));
  RandomStream stream(1);
  EXPECT_THAT(
      [&] { (void)BouncingDrift<3>::random(2, stream); },
      ::testing::ThrowsMessage<DimensionMismatchError>("dimension: size is 2; rule: must equal 3"));
}

}  // namespace
}  // namespace twincal
