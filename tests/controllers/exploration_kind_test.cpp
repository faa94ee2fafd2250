#include "twincal/controllers/exploration_kind.hpp"

#include <gtest/gtest.h>

namespace twincal {
namespace {

TEST(ExplorationKindNames, EverySpellingParsesBack) {
  for (const ExplorationKind v : {ExplorationKind::trace, ExplorationKind::weighted_trace,
                                  ExplorationKind::log_det, ExplorationKind::max_eigenvalue}) {
    EXPECT_EQ(parse_enum<ExplorationKind>(to_string(v), "exploration"), v);
  }
}

}  // namespace
}  // namespace twincal
