#include "twincal/samplers/candidate_sampler.hpp"

#include <gtest/gtest.h>

namespace twincal {
namespace {

TEST(CandidateSamplerNames, EverySpellingParsesBack) {
  for (const CandidateSampler v : {CandidateSampler::sobol, CandidateSampler::halton,
                                   CandidateSampler::random, CandidateSampler::latin_hypercube}) {
    EXPECT_EQ(parse_candidate_sampler(to_string(v)), v);
  }
}

}  // namespace
}  // namespace twincal
