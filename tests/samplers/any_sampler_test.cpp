#include "twincal/samplers/any_sampler.hpp"

#include <cstdint>

#include <gtest/gtest.h>

#include "twincal/samplers/balance_check.hpp"
#include "twincal/samplers/candidate_sampler.hpp"
#include "twincal/samplers/halton.hpp"
#include "twincal/samplers/sobol.hpp"
#include "twincal/samplers/testing/sampler_conformance.hpp"

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

// The conformance suite (samplers/testing/sampler_conformance.hpp) over every kind: a run-time
// choice is a Sampler like the samplers it wraps.
template <CandidateSampler Kind>
struct AnySamplerCase {
  using Sampler = AnySampler;
  static constexpr Index dimension = 5;
  static constexpr bool is_sequence = Kind != CandidateSampler::latin_hypercube;
  static constexpr bool is_randomized = true;
  static Sampler make(Index d, std::uint64_t seed) { return AnySampler(Kind, d, seed); }
};

using AnySamplerKinds = ::testing::Types<
    AnySamplerCase<CandidateSampler::sobol>, AnySamplerCase<CandidateSampler::halton>,
    AnySamplerCase<CandidateSampler::random>, AnySamplerCase<CandidateSampler::latin_hypercube>>;

}  // namespace
}  // namespace twincal

namespace twincal::conformance {
INSTANTIATE_TYPED_TEST_SUITE_P(AnySampler, SamplerConformance, AnySamplerKinds);
}  // namespace twincal::conformance
