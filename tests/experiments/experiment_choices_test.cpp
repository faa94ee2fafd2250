#include "twincal/experiments/experiment_choices.hpp"

#include <gtest/gtest.h>

#include "twincal/core/error.hpp"

namespace twincal {
namespace {

TEST(ExperimentChoices, EverySpellingParsesBack) {
  for (const TwinCase v : {TwinCase::body, TwinCase::door, TwinCase::analytic}) {
    EXPECT_EQ(parse_twin_case(to_string(v)), v);
  }
  for (const FilterScheme v : {FilterScheme::merwe, FilterScheme::julier, FilterScheme::cubature,
                               FilterScheme::fifth_degree, FilterScheme::simplex}) {
    EXPECT_EQ(parse_filter_scheme(to_string(v)), v);
  }
  for (const CandidateSampler v : {CandidateSampler::sobol, CandidateSampler::halton,
                                   CandidateSampler::random, CandidateSampler::latin_hypercube}) {
    EXPECT_EQ(parse_candidate_sampler(to_string(v)), v);
  }
  for (const ExplorationKind v : {ExplorationKind::trace, ExplorationKind::weighted_trace,
                                  ExplorationKind::log_det, ExplorationKind::max_eigenvalue}) {
    EXPECT_EQ(parse_exploration_kind(to_string(v)), v);
  }
}

TEST(ExperimentChoices, AnUnknownSpellingNamesTheSettingAndTheChoices) {
  try {
    (void)parse_filter_scheme("ukf", "--filter");
    FAIL() << "no error";
  } catch (const InvalidArgumentError& error) {
    EXPECT_EQ(error.argument(), "--filter");
    EXPECT_NE(std::string(error.what()).find("\"ukf\""), std::string::npos);
    EXPECT_NE(std::string(error.what()).find("merwe, julier, cubature"), std::string::npos);
  }
}

}  // namespace
}  // namespace twincal
