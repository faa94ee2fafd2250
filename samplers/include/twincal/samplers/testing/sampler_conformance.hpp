#pragma once
/// @file
/// The conformance suite every Sampler passes, as a GoogleTest typed test suite that users
/// instantiate for their own samplers (include it from a test, not from library code):
///
///     struct MyCase {
///       using Sampler = MySampler;
///       static constexpr Index dimension = 5;        // tested, with 1 and dimension + 1
///       static constexpr bool is_sequence = true;    // false: each fill is one design (LHS)
///       static constexpr bool is_randomized = true;  // the seed changes the points
///       static Sampler make(Index dimension, std::uint64_t seed) {
///         return MySampler(dimension, {.seed = seed});
///       }
///     };
///     namespace twincal::conformance {  // the suite's namespace
///     INSTANTIATE_TYPED_TEST_SUITE_P(Mine, SamplerConformance, ::testing::Types<MyCase>);
///     }
///
/// `make(d, s)` must give the sampler that `seed(s)` restarts. Checked: dimension() is the one
/// asked for; the same seed gives the same points and seed() restarts the stream; consecutive
/// fills give new points; discard(k) skips exactly what a fill of k would draw (for a design
/// sampler, a k-point design); a fill of n points equals n fills of one point and fills of
/// 16, 8, 4, 2, 1, 1 points (sequences only: a design is a property of its whole batch); a
/// fill into a strided block writes that block and nothing else; every point lies in [0, 1)^d;
/// empty requests change nothing; a bad dimension throws InvalidArgumentError, a fill of the
/// wrong rows DimensionMismatchError, and a throwing fill leaves the sampler and the matrix as
/// they were.
/// Batch sizes are aligned powers of two, so Sobol passes with `BalanceCheck::refuse`.
/// Points are compared exactly: a sampler is a deterministic function of its seed.

#include <cstdint>
#include <initializer_list>

#include <gtest/gtest.h>
#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/error.hpp"
#include "twincal/samplers/sampler.hpp"

namespace twincal::conformance {

template <typename Case>
class SamplerConformance : public ::testing::Test {
 protected:
  using SamplerType = typename Case::Sampler;
  static_assert(Sampler<SamplerType>, "Case::Sampler must satisfy twincal::Sampler");
  static constexpr Index case_dimension = Case::dimension;

  /// A fresh sampler of the case's dimension.
  static SamplerType make(std::uint64_t seed) { return Case::make(case_dimension, seed); }

  /// The next `count` points of `sampler`, one fill.
  static MatrixX draw(SamplerType& sampler, Index count) {
    MatrixX points(sampler.dimension(), count);
    sampler.fill(points);
    return points;
  }

  /// The next points of `sampler` in fills of `sizes` columns, side by side.
  static MatrixX draw_in_pieces(SamplerType& sampler, std::initializer_list<Index> sizes) {
    Index total = 0;
    for (const Index size : sizes) total += size;
    MatrixX points(sampler.dimension(), total);
    Index start = 0;
    for (const Index size : sizes) {
      sampler.fill(points.middleCols(start, size));
      start += size;
    }
    return points;
  }
};

TYPED_TEST_SUITE_P(SamplerConformance);

TYPED_TEST_P(SamplerConformance, DimensionIsTheOneAskedFor) {
  for (const Index d : {Index{1}, TypeParam::dimension, TypeParam::dimension + 1}) {
    auto sampler = TypeParam::make(d, 3);
    EXPECT_EQ(static_cast<Index>(sampler.dimension()), d);
    EXPECT_EQ(this->draw(sampler, 4).rows(), d);
  }
}

TYPED_TEST_P(SamplerConformance, TheSameSeedGivesTheSamePoints) {
  auto a = this->make(7);
  auto b = this->make(7);
  const MatrixX first = this->draw(a, 64);
  EXPECT_EQ(first, this->draw(b, 64));
  EXPECT_EQ(this->draw(a, 64), this->draw(b, 64));  // the streams stay in step
  // seed() restarts from the first point.
  b.seed(7);
  EXPECT_EQ(this->draw(b, 64), first);
  a.seed(11);  // the sampler that make(d, 11) builds, whatever was drawn before
  auto fresh = this->make(11);
  EXPECT_EQ(this->draw(a, 64), this->draw(fresh, 64));
  if constexpr (TypeParam::is_randomized) {
    auto other = this->make(8);
    EXPECT_NE(this->draw(other, 64), first) << "the case claims that the seed changes the points";
  }
}

TYPED_TEST_P(SamplerConformance, ConsecutiveFillsGiveNewPoints) {
  auto sampler = this->make(5);
  const MatrixX first = this->draw(sampler, 16);
  EXPECT_NE(this->draw(sampler, 16), first);
}

TYPED_TEST_P(SamplerConformance, DiscardSkipsWhatAFillWouldDraw) {
  auto filled = this->make(9);
  auto skipped = this->make(9);
  (void)this->draw(filled, 1024);
  skipped.discard(1024);
  EXPECT_EQ(this->draw(skipped, 64), this->draw(filled, 64));
  // In two steps: fills of 512 and 256 against discards of 512 and 256.
  auto filled_twice = this->make(10);
  auto skipped_twice = this->make(10);
  (void)this->draw_in_pieces(filled_twice, {512, 256});
  skipped_twice.discard(512);
  skipped_twice.discard(256);
  EXPECT_EQ(this->draw(skipped_twice, 64), this->draw(filled_twice, 64));
}

TYPED_TEST_P(SamplerConformance, ABatchEqualsFillsOfOnePointAndOfSmallerBatches) {
  if constexpr (!TypeParam::is_sequence) {
    GTEST_SKIP() << "each fill is one design: a batch is not a sequence of points";
  } else {
    auto whole = this->make(13);
    auto singles = this->make(13);
    auto pieces = this->make(13);
    const MatrixX all = this->draw(whole, 32);
    MatrixX one_by_one(all.rows(), all.cols());
    for (Index c = 0; c < all.cols(); ++c) singles.fill(one_by_one.col(c));
    EXPECT_EQ(one_by_one, all);
    EXPECT_EQ(this->draw_in_pieces(pieces, {16, 8, 4, 2, 1, 1}), all);
    EXPECT_EQ(this->draw(pieces, 32), this->draw(whole, 32));  // and the streams stay in step
  }
}

TYPED_TEST_P(SamplerConformance, FillsAStridedBlockAndNothingElse) {
  constexpr Index d = TypeParam::dimension;
  constexpr Index n = 16;
  constexpr double sentinel = -7.0;  // outside [0, 1): a point written there is seen
  auto plain = this->make(17);
  auto strided = this->make(17);
  const MatrixX expected = this->draw(plain, n);
  MatrixX frame = MatrixX::Constant(d + 3, n + 2, sentinel);
  strided.fill(frame.block(1, 1, d, n));  // outer stride d + 3, not d
  const MatrixX block = frame.block(1, 1, d, n);
  EXPECT_EQ(block, expected);
  frame.block(1, 1, d, n).setConstant(sentinel);
  EXPECT_TRUE((frame.array() == sentinel).all()) << "fill wrote outside its block";
}

TYPED_TEST_P(SamplerConformance, EveryPointLiesInTheUnitCube) {
  for (const std::uint64_t seed : {std::uint64_t{0}, std::uint64_t{19}}) {
    auto sampler = this->make(seed);
    for (int batch = 0; batch < 2; ++batch) {
      const MatrixX points = this->draw(sampler, 1024);
      for (Index c = 0; c < points.cols(); ++c) {
        for (Index r = 0; r < points.rows(); ++r) {
          ASSERT_TRUE(points(r, c) >= 0.0 && points(r, c) < 1.0)
              << "seed " << seed << ", batch " << batch << ", point " << c << ", coordinate " << r
              << " is " << points(r, c);
        }
      }
    }
  }
}

TYPED_TEST_P(SamplerConformance, EmptyRequestsChangeNothing) {
  auto sampler = this->make(23);
  auto reference = this->make(23);
  (void)this->draw(sampler, 16);
  (void)this->draw(reference, 16);
  MatrixX none(TypeParam::dimension, 0);
  sampler.fill(none);
  sampler.discard(0);
  EXPECT_EQ(this->draw(sampler, 16), this->draw(reference, 16));
}

TYPED_TEST_P(SamplerConformance, BadArgumentsThrowTypedErrorsAndChangeNothing) {
  EXPECT_THROW((void)TypeParam::make(0, 1), InvalidArgumentError);
  EXPECT_THROW((void)TypeParam::make(-1, 1), InvalidArgumentError);

  constexpr Index d = TypeParam::dimension;
  constexpr double sentinel = -7.0;
  auto sampler = this->make(29);
  auto reference = this->make(29);
  (void)this->draw(sampler, 16);  // not at the start: the position must survive too
  (void)this->draw(reference, 16);
  for (const Index rows : {d + 1, d - 1}) {
    MatrixX wrong = MatrixX::Constant(rows, 4, sentinel);
    try {
      sampler.fill(wrong);
      ADD_FAILURE() << "a fill of " << rows << " rows for dimension " << d << " did not throw";
    } catch (const DimensionMismatchError& error) {
      EXPECT_EQ(error.actual(), rows);
      EXPECT_EQ(error.expected(), d);
    } catch (const std::exception& error) {
      ADD_FAILURE() << "expected DimensionMismatchError, got: " << error.what();
    }
    EXPECT_TRUE((wrong.array() == sentinel).all()) << "a throwing fill wrote points";
  }
  EXPECT_EQ(this->draw(sampler, 16), this->draw(reference, 16));
}

REGISTER_TYPED_TEST_SUITE_P(SamplerConformance, DimensionIsTheOneAskedFor,
                            TheSameSeedGivesTheSamePoints, ConsecutiveFillsGiveNewPoints,
                            DiscardSkipsWhatAFillWouldDraw,
                            ABatchEqualsFillsOfOnePointAndOfSmallerBatches,
                            FillsAStridedBlockAndNothingElse, EveryPointLiesInTheUnitCube,
                            EmptyRequestsChangeNothing,
                            BadArgumentsThrowTypedErrorsAndChangeNothing);

}  // namespace twincal::conformance
