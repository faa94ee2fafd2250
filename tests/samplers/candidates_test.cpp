#include "twincal/samplers/candidates.hpp"

#include <string>

#include <gtest/gtest.h>

#include "twincal/core/error.hpp"
#include "twincal/samplers/halton.hpp"
#include "twincal/samplers/sobol.hpp"

namespace twincal {
namespace {

template <typename T>
class CandidatesTest : public ::testing::Test {
 public:
  static constexpr int N = T::value;
  static Vector<N> mean() {
    Vector<N> m(3);
    m << 0.2, -0.1, 0.05;
    return m;
  }
  // The paper's Sec. 3 setting: P = 1e-3·I, U_t = {|u_i − û*_i| <= 0.1}, 2^(2+d) candidates.
  static GaussianTransform<N> paper_transform() {
    return GaussianTransform<N>(mean(), 1e-3 * SquareMatrix<N>::Identity(3, 3));
  }
  static SobolOptions sobol_options() {
    return {.randomization = SobolRandomization::linear_matrix_scramble,
            .seed = 5,
            .balance = BalanceCheck::refuse};
  }
};

using Sizes =
    ::testing::Types<std::integral_constant<int, 3>, std::integral_constant<int, Dynamic>>;
TYPED_TEST_SUITE(CandidatesTest, Sizes);

TYPED_TEST(CandidatesTest, OneBatchIsTheSamplerThroughTheTransformMinusTheBoxOutliers) {
  const auto transform = TestFixture::paper_transform();
  const auto box = BoxSet<TestFixture::N>::cube(TestFixture::mean(), 0.1);
  Sobol sobol(3, TestFixture::sobol_options());
  const CandidateSet<TestFixture::N> set = draw_candidates(sobol, transform, box, {.count = 32});

  Sobol replay(3, TestFixture::sobol_options());
  MatrixX u(3, 32);
  replay.fill(u);
  Matrix<TestFixture::N, Dynamic> expected = transform(u);
  const Index kept = box.keep_inside(expected);
  EXPECT_EQ(set.drawn(), 32);
  EXPECT_EQ(set.survived(), kept);
  EXPECT_EQ(set.points(), expected.leftCols(kept));
  EXPECT_EQ(sobol.position(), 32U);
  // 0.1 is 3.16 σ: each coordinate falls outside with probability 0.0016, and the zero point
  // of the sequence is scrambled away from the clipped tail, so nearly all survive.
  EXPECT_GE(set.survived(), 30);
}

TYPED_TEST(CandidatesTest, KeepDrawingUntilEnoughSurvive) {
  const auto transform = TestFixture::paper_transform();
  // Half a standard deviation: about 38% per coordinate, 5.6% of points survive.
  const auto box = BoxSet<TestFixture::N>::cube(TestFixture::mean(), 0.5 * std::sqrt(1e-3));
  Sobol sobol(3, TestFixture::sobol_options());
  const CandidateSet<TestFixture::N> set =
      draw_candidates(sobol, transform, box, {.count = 32, .keep_drawing = true});
  EXPECT_TRUE(set.complete());
  EXPECT_EQ(set.points().cols(), 32);
  EXPECT_GE(set.survived(), 32);
  EXPECT_EQ(set.drawn() % 32, 0);
  EXPECT_GT(set.drawn(), 32 * 10);  // expected 32 / 0.056 ≈ 570 points, i.e. ~18 batches
  EXPECT_EQ(static_cast<Index>(sobol.position()), set.drawn());  // aligned blocks of 32
  for (Index c = 0; c < set.points().cols(); ++c) EXPECT_TRUE(box.contains(set.points().col(c)));
}

TYPED_TEST(CandidatesTest, KeepDrawingIsBoundedAndReportsAShortfall) {
  const auto transform = TestFixture::paper_transform();
  Vector<TestFixture::N> far = TestFixture::mean();
  far(0) += 0.5;  // 16 σ away: nothing survives
  const auto box = BoxSet<TestFixture::N>::cube(far, 0.01);
  Halton halton(3);
  const CandidateSet<TestFixture::N> set = draw_candidates(
      halton, transform, box, {.count = 16, .keep_drawing = true, .max_batches = 5});
  EXPECT_FALSE(set.complete());
  EXPECT_EQ(set.drawn(), 80);
  EXPECT_EQ(set.survived(), 0);
  EXPECT_EQ(set.points().cols(), 0);
}

TYPED_TEST(CandidatesTest, RedrawingReusesTheBuffersAndContinuesTheSequence) {
  const auto transform = TestFixture::paper_transform();
  const auto box = BoxSet<TestFixture::N>::cube(TestFixture::mean(), 0.1);
  Sobol sobol(3, TestFixture::sobol_options());
  CandidateSet<TestFixture::N> set;
  set.draw(sobol, transform, box, {.count = 32});
  const Matrix<TestFixture::N, Dynamic> first = set.points();
  const double* storage = set.points().data();
  set.draw(sobol, transform, box, {.count = 32});
  EXPECT_EQ(set.points().data(), storage);  // same buffer: nothing reallocated
  EXPECT_EQ(sobol.position(), 64U);

  Sobol replay(3, TestFixture::sobol_options());
  replay.discard(32);
  const CandidateSet<TestFixture::N> second =
      draw_candidates(replay, transform, box, {.count = 32});
  EXPECT_EQ(set.points(), second.points());
  EXPECT_NE(set.points().leftCols(4), first.leftCols(4));

  // A rejected draw leaves the set as it was.
  const auto wrong_box = BoxSet<Dynamic>::cube(VectorX::Zero(2), 0.1);
  if constexpr (TestFixture::N == Dynamic) {
    EXPECT_THROW(set.draw(sobol, transform, wrong_box), DimensionMismatchError);
    EXPECT_EQ(set.points(), second.points());
    EXPECT_EQ(set.drawn(), 32);
  }
}

TEST(Candidates, RejectsMismatchesBeforeDrawing) {
  const GaussianTransform<Dynamic> transform(VectorX::Zero(3), MatrixX::Identity(3, 3));
  const auto box = BoxSet<Dynamic>::cube(VectorX::Zero(3), 1.0);
  Sobol sobol(2);
  try {
    (void)draw_candidates(sobol, transform, box);
    FAIL();
  } catch (const DimensionMismatchError& e) {
    EXPECT_EQ(std::string(e.what()), "sampler: dimension is 2; rule: must equal 3");
  }
  EXPECT_EQ(sobol.position(), 0U);
  Sobol right(3);
  try {
    (void)draw_candidates(right, transform, box, {.count = 0});
    FAIL();
  } catch (const InvalidArgumentError& e) {
    EXPECT_EQ(std::string(e.what()), "options: count: value is 0; rule: must be >= 1");
  }
  const auto small_box = BoxSet<Dynamic>::cube(VectorX::Zero(2), 1.0);
  EXPECT_THROW((void)draw_candidates(right, transform, small_box), DimensionMismatchError);
  EXPECT_EQ(right.position(), 0U);
}

}  // namespace
}  // namespace twincal
