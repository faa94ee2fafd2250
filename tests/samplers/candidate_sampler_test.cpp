#include "twincal/samplers/candidate_sampler.hpp"

#include <gtest/gtest.h>

namespace twincal {
namespace {

TEST(CandidateSamplerNames, EverySpellingParsesBack) {
  for (const CandidateSampler v : {CandidateSampler::sobol, CandidateSampler::halton,
                                   CandidateSampler::random, CandidateSampler::latin_hypercube}) {
    EXPECT_EQ(parse_enum<CandidateSampler>(to_string(v), "sampler"), v);
  }
}

}  // namespace
}  // namespace twincal
