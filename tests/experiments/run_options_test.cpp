#include "twincal/experiments/run_options.hpp"

#include <gtest/gtest.h>

namespace twincal {
namespace {

TEST(RunOptions, DefaultsUseAllCoresAndValidate) {
  const RunOptions options;
  EXPECT_EQ(options.threads, 0);
  EXPECT_FALSE(options.validate().has_value());
}

TEST(RunOptions, RejectsNegativeThreadCounts) {
  const RunOptions options{.threads = -1, .progress = false};
  ASSERT_TRUE(options.validate().has_value());
  EXPECT_NE(options.validate()->find("threads: value is -1; rule: must be >= 0 (0: all cores)"),
            std::string::npos);
}

}  // namespace
}  // namespace twincal
