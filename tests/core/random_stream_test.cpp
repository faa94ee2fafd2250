#include "twincal/core/random_stream.hpp"

#include <set>
#include <vector>

#include <gtest/gtest.h>

namespace twincal {
namespace {

std::vector<std::uint64_t> draws(RandomStream stream, int count) {
  std::vector<std::uint64_t> out;
  for (int i = 0; i < count; ++i) out.push_back(stream());
  return out;
}

TEST(RandomStream, SameSeedSameNumbers) {
  EXPECT_EQ(draws(RandomStream(42), 16), draws(RandomStream(42), 16));
  EXPECT_NE(draws(RandomStream(42), 16), draws(RandomStream(43), 16));
  EXPECT_EQ(RandomStream(42).seed(), 42U);
}

TEST(RandomStream, EngineIsTheStandardMt19937_64) {
  // The 10000th output of a default-seeded mt19937_64 is fixed by the C++ standard
  // ([rand.predef]); with seed 5489 our stream is that engine.
  RandomStream stream(5489);
  stream.discard(9999);
  EXPECT_EQ(stream(), 9981545732273789042ULL);
}

TEST(RandomStream, SubstreamsDependOnSeedAndKeyOnly) {
  RandomStream root(7);
  const RandomStream before = root.substream("noise");
  (void)root();  // drawing from the parent does not move its substreams
  (void)root();
  EXPECT_EQ(root.substream("noise").seed(), before.seed());
  EXPECT_EQ(draws(root.substream("noise"), 8), draws(before, 8));
}

TEST(RandomStream, DistinctKeysGiveDistinctStreams) {
  const RandomStream root(2023);
  std::set<std::uint64_t> seeds;
  for (std::uint64_t i = 0; i < 1000; ++i) seeds.insert(root.substream(i).seed());
  seeds.insert(root.substream("run").seed());
  seeds.insert(root.substream("controller").seed());
  seeds.insert(root.seed());
  EXPECT_EQ(seeds.size(), 1003U);
  EXPECT_NE(root.substream("run").substream(0).seed(), root.substream(0).seed());
}

TEST(RandomStream, DerivationIsTheDocumentedSplitMix) {
  const RandomStream root(99);
  EXPECT_EQ(root.substream("run").seed(), splitmix64(splitmix64(99) ^ fnv1a64("run")));
  EXPECT_EQ(root.substream(std::uint64_t{3}).seed(), splitmix64(splitmix64(99) ^ splitmix64(3)));
  // Reference values of the published algorithms.
  EXPECT_EQ(fnv1a64(""), 0xcbf29ce484222325ULL);
  EXPECT_EQ(fnv1a64("a"), 0xaf63dc4c8601ec8cULL);
  EXPECT_EQ(splitmix64(0), 0xe220a8397b1dcdafULL);
}

TEST(RandomStream, UniformAndNormalHaveTheRightMoments) {
  RandomStream stream(1);
  constexpr int n = 200000;
  double sum_u = 0.0;
  double sum_z = 0.0;
  double sum_z2 = 0.0;
  for (int i = 0; i < n; ++i) {
    const double u = stream.uniform();
    ASSERT_GE(u, 0.0);
    ASSERT_LT(u, 1.0);
    sum_u += u;
    const double z = stream.normal();
    sum_z += z;
    sum_z2 += z * z;
  }
  // 5-sigma bands for the sample means.
  EXPECT_NEAR(sum_u / n, 0.5, 5.0 * std::sqrt(1.0 / 12.0 / n));
  EXPECT_NEAR(sum_z / n, 0.0, 5.0 / std::sqrt(n));
  EXPECT_NEAR(sum_z2 / n, 1.0, 5.0 * std::sqrt(2.0 / n));
}

TEST(RandomStream, UniformIntStaysInRangeAndFillNormalFillsEveryEntry) {
  RandomStream stream(3);
  for (int i = 0; i < 1000; ++i) {
    const int k = stream.uniform_int(2, 5);
    ASSERT_GE(k, 2);
    ASSERT_LE(k, 5);
  }
  Eigen::Matrix<double, 3, 4> m = Eigen::Matrix<double, 3, 4>::Constant(1e300);
  stream.fill_normal(m);
  EXPECT_LT(m.cwiseAbs().maxCoeff(), 10.0);
  RandomStream a(11);
  RandomStream b(11);
  Eigen::MatrixXd ma(2, 3);
  a.fill_normal(ma);
  for (Index c = 0; c < 3; ++c) {
    for (Index r = 0; r < 2; ++r) EXPECT_EQ(ma(r, c), b.normal());
  }
}

}  // namespace
}  // namespace twincal
