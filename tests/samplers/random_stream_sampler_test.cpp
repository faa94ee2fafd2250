#include "twincal/samplers/random_stream_sampler.hpp"

#include <cstdint>
#include <string>

#include <gtest/gtest.h>
#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/samplers/sampler.hpp"

namespace twincal {
namespace {

struct RawDrawOptions {
  std::uint64_t seed = 0;
};

/// The smallest Draws policy: each coordinate is one raw engine draw, kept exactly as a double
/// of its top 53 bits, so a test can compare against the stream.
struct RawDraws {
  using Options = RawDrawOptions;
  void fill(RandomStream& stream, const Options& /*options*/, Eigen::Ref<MatrixX> points) const {
    for (Index c = 0; c < points.cols(); ++c) {
      for (Index r = 0; r < points.rows(); ++r) {
        points(r, c) = static_cast<double>(stream() >> 11U);
      }
    }
  }
  void discard(RandomStream& stream, const Options& /*options*/, Index dimension,
               std::uint64_t count) const {
    stream.discard(count * static_cast<std::uint64_t>(dimension));
  }
};

using RawSampler = RandomStreamSampler<RawDraws>;
static_assert(ConstructibleSampler<RawSampler>);

[[nodiscard]] double first_draw(std::uint64_t seed) {
  RandomStream stream(seed);
  return static_cast<double>(stream() >> 11U);
}

TEST(RandomStreamSampler, RefusesAnEmptyDimension) {
  try {
    const RawSampler bad(0);
    FAIL() << "no error";
  } catch (const InvalidArgumentError& e) {
    EXPECT_EQ(e.argument(), "dimension");
    EXPECT_EQ(std::string(e.what()), "dimension: value is 0; rule: must be >= 1");
  }
}

TEST(RandomStreamSampler, ChecksTheRowsBeforeDrawing) {
  RawSampler sampler(2, {.seed = 3});
  MatrixX wrong(3, 1);
  EXPECT_THROW(sampler.fill(wrong), DimensionMismatchError);
  MatrixX point(2, 1);
  sampler.fill(point);
  EXPECT_EQ(point(0, 0), first_draw(3));
}

TEST(RandomStreamSampler, SeedRestartsTheStreamAndIsKeptInTheOptions) {
  RawSampler sampler(1, {.seed = 1});
  MatrixX point(1, 1);
  sampler.fill(point);
  sampler.seed(5);
  EXPECT_EQ(sampler.options().seed, 5U);
  sampler.fill(point);
  EXPECT_EQ(point(0, 0), first_draw(5));
}

TEST(RandomStreamSampler, DiscardIsThePolicys) {
  RawSampler skipped(2, {.seed = 9});
  RawSampler drawn(2, {.seed = 9});
  MatrixX points(2, 3);
  skipped.discard(2);
  drawn.fill(points);
  MatrixX next(2, 1);
  skipped.fill(next);
  EXPECT_EQ(next.col(0), points.col(2));
}

TEST(RandomStreamSampler, ASavedStreamContinuesWhereItWasSaved) {
  RawSampler sampler(3, {.seed = 11});
  MatrixX points(3, 1);
  sampler.fill(points);
  const RandomStream saved = sampler.stream();
  sampler.fill(points);
  RawSampler restored(3, {.seed = 2});
  restored.set_stream(saved);
  EXPECT_EQ(restored.options().seed, 11U);
  MatrixX again(3, 1);
  restored.fill(again);
  EXPECT_EQ(again, points);
}

}  // namespace
}  // namespace twincal
