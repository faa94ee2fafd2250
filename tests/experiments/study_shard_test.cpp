#include "twincal/experiments/study_shard.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "twincal/core/error.hpp"

namespace twincal {
namespace {

using ::testing::HasSubstr;

TEST(StudyShard, TheWholeStudyByDefault) {
  const StudyShard shard;
  EXPECT_TRUE(shard.whole());
  EXPECT_FALSE(shard.validate());
  for (Index k = 0; k < 5; ++k) EXPECT_TRUE(shard.holds(k));
}

TEST(StudyShard, EveryEpisodeBelongsToExactlyOneShard) {
  for (Index k = 0; k < 20; ++k) {
    int holders = 0;
    for (Index i = 0; i < 3; ++i) holders += StudyShard{.index = i, .count = 3}.holds(k) ? 1 : 0;
    EXPECT_EQ(holders, 1) << "episode " << k;
  }
  EXPECT_TRUE((StudyShard{.index = 2, .count = 3}.holds(5)));
}

TEST(StudyShard, ValidateNamesTheFieldAndTheRule) {
  EXPECT_THAT((StudyShard{.index = 0, .count = 0}.validate().value()),
              HasSubstr("count: value is 0; rule: must be >= 1"));
  EXPECT_THAT((StudyShard{.index = 3, .count = 3}.validate().value()),
              HasSubstr("index: value is 3; rule: must lie in [0, count) = [0, 3)"));
  EXPECT_TRUE((StudyShard{.index = -1, .count = 3}.validate().has_value()));
}

TEST(ParseStudyShard, ReadsIndexSlashCount) {
  const StudyShard shard = parse_study_shard("2/8", "--shard");
  EXPECT_EQ(shard.index, 2);
  EXPECT_EQ(shard.count, 8);
}

TEST(ParseStudyShard, RefusesWhatIsNotTwoIntegersOrBreaksARule) {
  for (const char* text : {"", "2", "2/", "/8", "a/8", "2/8x", "2 /8", "2/8/1", "-0x1/2"}) {
    try {
      (void)parse_study_shard(text, "--shard");
      ADD_FAILURE() << "accepted \"" << text << "\"";
    } catch (const InvalidArgumentError& error) {
      EXPECT_THAT(error.what(), HasSubstr("--shard: value is \""));
      EXPECT_EQ(error.argument(), "--shard");
    }
  }
  EXPECT_THROW((void)parse_study_shard("8/8", "--shard"), InvalidArgumentError);
  EXPECT_THROW((void)parse_study_shard("0/0", "--shard"), InvalidArgumentError);
  EXPECT_THROW((void)parse_study_shard("-1/4", "--shard"), InvalidArgumentError);
}

}  // namespace
}  // namespace twincal
