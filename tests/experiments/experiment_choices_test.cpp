#include "twincal/experiments/experiment_choices.hpp"

#include <gtest/gtest.h>

#include "twincal/core/error.hpp"

namespace twincal {
namespace {

TEST(ExperimentChoices, EverySpellingParsesBack) {
  for (const TwinCase v : {TwinCase::body, TwinCase::door, TwinCase::analytic}) {
    EXPECT_EQ(parse_enum<TwinCase>(to_string(v), "case"), v);
  }
}

}  // namespace
}  // namespace twincal
