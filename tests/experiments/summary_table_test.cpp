#include "twincal/experiments/summary_table.hpp"

#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace twincal {
namespace {

using nlohmann::json;

json summary_episode(const std::string& controller, Index run, double residual, double error,
                     bool diverged, bool lost = false, Index fallbacks = 0, Index dropped = 0) {
  return json{{"group", "g"},
              {"controller", controller},
              {"run", run},
              {"relative_residual", residual},
              {"estimation_error", error},
              {"diverged_at", diverged ? json(4) : json(nullptr)},
              {"seconds_per_assembly", 2e-6 * static_cast<double>(run + 1)},
              {"q_evaluations_per_assembly", 10.0},
              {"lost", lost},
              {"fallbacks", fallbacks},
              {"dropped_measurements", dropped}};
}

TEST(Summarize, MediansOverTheRunsThatDidNotDivergeAndCountsDivergences) {
  const json groups = json::array(
      {json{{"name", "g"}, {"config", json{{"controllers", {"default", "w=1", "baseline"}}}}}});
  const std::vector<json> episodes{
      summary_episode("w=1", 0, 0.3, 0.1, false),    summary_episode("w=1", 1, 0.1, 0.4, false),
      summary_episode("w=1", 2, 0.2, 0.2, false),    summary_episode("w=1", 3, 9.0, 9.0, true),
      summary_episode("default", 0, 0.5, 0.5, true), summary_episode("default", 1, 0.7, 0.6, false),
      summary_episode("default", 2, 0.1, 0.2, false)};
  const std::vector<SummaryRow> rows = summarize(groups, episodes);
  ASSERT_EQ(rows.size(), 2U);  // baseline has no episodes
  EXPECT_EQ(rows[0].controller, "default");
  EXPECT_EQ(rows[0].runs, 3);
  EXPECT_EQ(rows[0].divergences, 1);
  EXPECT_DOUBLE_EQ(rows[0].median_relative_residual, 0.4);  // of 0.7 and 0.1
  EXPECT_DOUBLE_EQ(rows[0].median_estimation_error, 0.4);
  EXPECT_DOUBLE_EQ(rows[0].seconds_per_assembly, 4e-6);
  EXPECT_EQ(rows[1].controller, "w=1");
  EXPECT_EQ(rows[1].divergences, 1);
  EXPECT_DOUBLE_EQ(rows[1].median_relative_residual, 0.2);
  EXPECT_DOUBLE_EQ(rows[1].median_estimation_error, 0.2);
  EXPECT_DOUBLE_EQ(rows[1].q_evaluations_per_assembly, 10.0);
  const std::string table = format_summary(rows);
  EXPECT_NE(table.find("w=1"), std::string::npos);
}

TEST(Summarize, CountsLostRunsBesideTheDivergedOnes) {
  const json groups = json::array(
      {json{{"name", "g"}, {"config", json{{"controllers", {"baseline", "default"}}}}}});
  // A lost run may have diverged or not; it stays in the medians unless it diverged.
  const std::vector<json> episodes{summary_episode("baseline", 0, 0.3, 1.0, false),
                                   summary_episode("baseline", 1, 0.3, 1.0, false),
                                   summary_episode("default", 0, 0.9, 3.0, false, true),
                                   summary_episode("default", 1, 0.1, 0.2, false),
                                   summary_episode("default", 2, 0.5, 20.0, true, true)};
  const std::vector<SummaryRow> rows = summarize(groups, episodes);
  ASSERT_EQ(rows.size(), 2U);
  EXPECT_EQ(rows[0].lost, 0);
  EXPECT_EQ(rows[1].runs, 3);
  EXPECT_EQ(rows[1].divergences, 1);
  EXPECT_EQ(rows[1].lost, 2);
  EXPECT_DOUBLE_EQ(rows[1].median_estimation_error, 1.6);  // of 3.0 and 0.2
  const std::string table = format_summary(rows);
  EXPECT_THAT(table, ::testing::ContainsRegex("runs +diverged +lost +fallbacks +dropped +med"));
  EXPECT_THAT(table, ::testing::ContainsRegex("baseline +2 +0 +0 "));
  EXPECT_THAT(table, ::testing::ContainsRegex("default +3 +1 +2 "));
}

TEST(Summarize, LeavesTheLostCountOpenForRecordsFromBeforeTheRule) {
  const json groups =
      json::array({json{{"name", "g"}, {"config", json{{"controllers", {"default"}}}}}});
  json old = summary_episode("default", 0, 0.1, 0.2, false);
  old.erase("lost");
  const std::vector<SummaryRow> rows =
      summarize(groups, {old, summary_episode("default", 1, 0.1, 0.2, false, true)});
  ASSERT_EQ(rows.size(), 1U);
  EXPECT_FALSE(rows[0].lost.has_value());
  EXPECT_THAT(format_summary(rows), ::testing::ContainsRegex("default +2 +0 +- "));
}

TEST(Summarize, SumsTheFallbacksAndTheDroppedMeasurementsOverTheRuns) {
  const json groups =
      json::array({json{{"name", "g"}, {"config", json{{"controllers", {"baseline", "active"}}}}}});
  const std::vector<json> episodes{summary_episode("baseline", 0, 0.3, 1.0, false),
                                   summary_episode("active", 0, 0.1, 0.2, false, false, 3, 1),
                                   summary_episode("active", 1, 0.1, 0.2, false, false, 0, 0),
                                   summary_episode("active", 2, 0.9, 3.0, false, true, 40, 6)};
  const std::vector<SummaryRow> rows = summarize(groups, episodes);
  ASSERT_EQ(rows.size(), 2U);
  EXPECT_EQ(rows[0].fallbacks, 0);
  EXPECT_EQ(rows[0].dropped_measurements, 0);
  EXPECT_EQ(rows[1].fallbacks, 43);
  EXPECT_EQ(rows[1].dropped_measurements, 7);
  EXPECT_THAT(format_summary(rows), ::testing::ContainsRegex("active +3 +0 +1 +43 +7 "));
}

TEST(Summarize, LeavesTheFallbackCountOpenForRecordsFromBeforeIt) {
  const json groups =
      json::array({json{{"name", "g"}, {"config", json{{"controllers", {"active"}}}}}});
  json old = summary_episode("active", 0, 0.1, 0.2, false);
  old.erase("fallbacks");
  old.erase("dropped_measurements");
  const std::vector<SummaryRow> rows =
      summarize(groups, {old, summary_episode("active", 1, 0.1, 0.2, false, false, 2)});
  ASSERT_EQ(rows.size(), 1U);
  EXPECT_FALSE(rows[0].fallbacks.has_value());
  EXPECT_FALSE(rows[0].dropped_measurements.has_value());
  EXPECT_THAT(format_summary(rows), ::testing::ContainsRegex("active +2 +0 +0 +- +- "));
}

TEST(Summarize, AllRunsDivergedLeavesNoMedian) {
  const json groups =
      json::array({json{{"name", "g"}, {"config", json{{"controllers", {"default"}}}}}});
  const std::vector<SummaryRow> rows =
      summarize(groups, {summary_episode("default", 0, 1.0, 20.0, true)});
  ASSERT_EQ(rows.size(), 1U);
  EXPECT_TRUE(std::isnan(rows[0].median_relative_residual));
  EXPECT_NE(format_summary(rows).find(" - "), std::string::npos);
}

TEST(FormatDepartures, OneLinePerGroupWithARecordedDeparture) {
  const json groups = json::array(
      {json{{"name", "analytic/all/contact/d=3/s=1"}, {"twin", {{"quadratic_departure", 0.1954}}}},
       json{{"name", "external/A"}, {"twin", {{"quadratic_departure", nullptr}}}},
       json{{"name", "old"}, {"twin", {{"dimension", 3}}}}});
  const std::string text = format_departures(groups);
  EXPECT_THAT(text, ::testing::HasSubstr("analytic/all/contact/d=3/s=1: Q² departs 0.195"));
  EXPECT_THAT(text, ::testing::Not(::testing::HasSubstr("external/A")));
  EXPECT_THAT(text, ::testing::Not(::testing::HasSubstr("old")));
  EXPECT_EQ(format_departures(json::array()), "");
}

TEST(FormatActiveModels, OneLinePerGroupWithAnActiveControllerNamingWhatItsModelsComeFrom) {
  const json groups = json::array(
      {json{{"name", "body/all"},
            {"twin", {{"active_models", {{"from", "deviations"}, {"key_points", 40}}}}}},
       json{{"name", "external/all"},
            {"twin", {{"active_models", {{"from", "quality"}, {"key_points", 0}}}}}},
       json{{"name", "analytic/all/contact"},
            {"twin", {{"active_models", {{"from", "quality"}, {"key_points", 60}}}}}},
       json{{"name", "door/A"}, {"twin", {{"active_models", nullptr}}}},
       json{{"name", "old"}, {"twin", {{"dimension", 3}}}}});
  EXPECT_EQ(format_active_models(groups),
            "body/all: the active controller models Q² from the twin's 40 key points' "
            "deviations\nexternal/all: the active controller models Q² from the quality alone "
            "(the twin answers no key points: docs/external.md, key_points)\n"
            "analytic/all/contact: the active controller models Q² from the quality alone "
            "(surrogate.from_deviations is off)\n");
  EXPECT_EQ(format_active_models(json::array()), "");
}

TEST(FormatOptimumSearches, OneLinePerGroupWhoseTwinOrPlantSearchedU0) {
  const json groups = json::array(
      {json{{"name", "external/all"},
            {"twin",
             {{"optimum_search",
               {{"evaluations_per_assembly", 338.0}, {"requests_per_assembly", 98.5}}}}}},
       json{{"name", "analytic/all"}, {"twin", {{"optimum_search", nullptr}}}},
       json{{"name", "external/kept"},
            {"twin",
             {{"optimum_search",
               {{"evaluations_per_assembly", 98.0},
                {"requests_per_assembly", 98.0},
                {"read_from_file", true}}},
              {"plant_optimum_search",
               {{"evaluations_per_assembly", 200.0}, {"requests_per_assembly", 100.0}}}}}},
       json{{"name", "old"}, {"twin", {{"dimension", 3}}}}});
  const std::string text = format_optimum_searches(groups);
  EXPECT_EQ(text,
            "external/all: u0 searched in 338.0 twin evaluations per assembly (98.5 "
            "requests)\nexternal/kept: u0 searched in 98.0 twin evaluations per assembly (98.0 "
            "requests), read from its optima_file\nexternal/kept: the plant's u0 searched in "
            "200.0 twin evaluations per assembly (100.0 requests)\n");
  EXPECT_EQ(format_optimum_searches(json::array()), "");
}

}  // namespace
}  // namespace twincal
