#include "twincal/experiments/any_sampler.hpp"

#include <gtest/gtest.h>

namespace twincal {
namespace {

TEST(AnySampler, DrawsWhatTheChosenSamplerDraws) {
  AnySampler any(CandidateSampler::sobol, 3, 42);
  Sobol sobol(3, {.randomization = SobolRandomization::linear_matrix_scramble,
                  .seed = 42,
                  .balance = BalanceCheck::ignore});
  Eigen::MatrixXd a(3, 8);
  Eigen::MatrixXd b(3, 8);
  any.fill(a);
  sobol.fill(b);
  EXPECT_EQ(a, b);
  any.discard(8);
  sobol.discard(8);
  any.fill(a);
  sobol.fill(b);
  EXPECT_EQ(a, b);

  AnySampler halton(CandidateSampler::halton, 2, 7);
  Halton reference(2, {.scramble = true, .seed = 7});
  Eigen::MatrixXd c(2, 5);
  Eigen::MatrixXd d(2, 5);
  halton.fill(c);
  reference.fill(d);
  EXPECT_EQ(c, d);
  EXPECT_EQ(halton.dimension(), 2);
}

TEST(AnySampler, EveryKindFillsTheUnitCube) {
  for (const CandidateSampler kind :
       {CandidateSampler::sobol, CandidateSampler::halton, CandidateSampler::random,
        CandidateSampler::latin_hypercube}) {
    AnySampler sampler(kind, 4, 3);
    Eigen::MatrixXd points(4, 16);
    sampler.fill(points);
    EXPECT_GE(points.minCoeff(), 0.0);
    EXPECT_LT(points.maxCoeff(), 1.0);
    Eigen::MatrixXd again(4, 16);
    sampler.seed(3);
    sampler.fill(again);
    EXPECT_EQ(points, again) << to_string(kind);
  }
}

}  // namespace
}  // namespace twincal
