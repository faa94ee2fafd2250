#include "twincal/experiments/sweep.hpp"

#include <gtest/gtest.h>

#include "twincal/core/error.hpp"

namespace twincal {
namespace {

using nlohmann::json;

TEST(PaperStudy, IsEveryCaseTimesTheFourLocatorSets) {
  const std::vector<TwinCase> cases{TwinCase::body, TwinCase::door};
  const std::vector<ExperimentGroup> groups = paper_study(cases);
  ASSERT_EQ(groups.size(), 8U);
  EXPECT_EQ(groups[0].config.group_name(), "body/A");
  EXPECT_EQ(groups[3].config.group_name(), "body/ABC");
  EXPECT_EQ(groups[7].config.group_name(), "door/ABC");
  EXPECT_EQ(groups[5].tags, (json{{"case", "door"}, {"locators", "B"}}));
  EXPECT_EQ(groups[5].config.controllers.size(), 14U);
  ExperimentConfig named;
  named.name = "x";
  EXPECT_THROW((void)paper_study(cases, named), InvalidArgumentError);
}

TEST(ScalingStudy, IsOneGroupPerDimensionOnTheAnalyticTwinAndThreeLocatorSetsOnAFemTwin) {
  const std::vector<Index> dimensions{1, 12, 32};
  ExperimentConfig base;
  base.runs = 3;
  const std::vector<ExperimentGroup> groups = scaling_study(TwinCase::analytic, dimensions, base);
  ASSERT_EQ(groups.size(), 3U);
  EXPECT_EQ(groups[1].config.group_name(), "analytic/all/d=12");
  EXPECT_EQ(groups[1].config.analytic_dimension, 12);
  EXPECT_EQ(groups[1].config.locators, "all");
  EXPECT_EQ(groups[1].config.runs, 3);
  EXPECT_EQ(groups[2].tags, (json{{"study", "scaling"}, {"dimension", 32}}));

  const std::vector<ExperimentGroup> body = scaling_study(TwinCase::body, {}, base);
  ASSERT_EQ(body.size(), 3U);
  EXPECT_EQ(body[1].config.group_name(), "body/ABC");
  EXPECT_EQ(body[2].tags, (json{{"study", "scaling"}, {"locators", "all"}}));

  EXPECT_THROW((void)scaling_study(TwinCase::door, dimensions, base), InvalidArgumentError);
  const std::vector<Index> zero{0};
  EXPECT_THROW((void)scaling_study(TwinCase::analytic, zero, base), InvalidArgumentError);
  ExperimentConfig named;
  named.name = "x";
  EXPECT_THROW((void)scaling_study(TwinCase::analytic, dimensions, named), InvalidArgumentError);
}

TEST(NonlinearityStudy, IsOneGroupPerDimensionAndStrength) {
  ExperimentConfig base;
  base.nonlinearity = Nonlinearity::stiffening;
  base.runs = 2;
  const std::vector<Index> dimensions{3, 12};
  const std::vector<double> strengths{0.0, 0.5, 2.0};
  const std::vector<ExperimentGroup> groups = nonlinearity_study(dimensions, strengths, base);
  ASSERT_EQ(groups.size(), 6U);
  EXPECT_EQ(groups[4].config.group_name(), "analytic/all/stiffening/d=12/s=0.5");
  EXPECT_EQ(groups[4].config.twin_case, TwinCase::analytic);
  EXPECT_EQ(groups[4].config.analytic_dimension, 12);
  EXPECT_EQ(groups[4].config.strength, 0.5);
  EXPECT_EQ(groups[4].config.runs, 2);
  EXPECT_EQ(groups[4].tags, (json{{"study", "nonlinearity"},
                                  {"nonlinearity", "stiffening"},
                                  {"dimension", 12},
                                  {"strength", 0.5}}));
  ExperimentConfig none;
  EXPECT_THROW((void)nonlinearity_study(dimensions, strengths, none), InvalidArgumentError);
  base.nonlinearity = Nonlinearity::contact;
  const std::vector<double> too_strong{2.0};
  EXPECT_THROW((void)nonlinearity_study(dimensions, too_strong, base), InvalidArgumentError);
  EXPECT_THROW((void)nonlinearity_study({}, strengths, base), InvalidArgumentError);
}

TEST(ExpandSweep, IsTheCartesianProductOfTheAxesLastFastest) {
  const json sweep = json::parse(R"({
    "base": {"case": "analytic", "locators": "ABC", "runs": 2},
    "axes": {"filter": ["merwe", "cubature"], "w": [0.3, 1.0], "dimension": [3, 4]}})");
  const std::vector<ExperimentGroup> groups = expand_sweep(sweep);
  ASSERT_EQ(groups.size(), 8U);
  // Axes in key order: dimension, filter, w.
  EXPECT_EQ(groups[0].config.group_name(), "analytic/ABC/dimension=3 filter=merwe w=0.3");
  EXPECT_EQ(groups[1].config.group_name(), "analytic/ABC/dimension=3 filter=merwe w=1.0");
  EXPECT_EQ(groups[7].config.group_name(), "analytic/ABC/dimension=4 filter=cubature w=1.0");
  EXPECT_EQ(groups[7].config.analytic_dimension, 4);
  EXPECT_EQ(groups[7].config.filter, FilterScheme::cubature);
  EXPECT_EQ(groups[1].config.controllers, std::vector{ControllerSpec::lookahead(1.0)});
  EXPECT_EQ(groups[2].tags, (json{{"dimension", 3}, {"filter", "cubature"}, {"w", 0.3}}));
  EXPECT_EQ(groups[2].config.runs, 2);
}

TEST(ExpandSweep, WithoutAxesIsTheBaseAlone) {
  const std::vector<ExperimentGroup> groups =
      expand_sweep(json::parse(R"({"base": {"case": "analytic", "name": "only"}})"));
  ASSERT_EQ(groups.size(), 1U);
  EXPECT_EQ(groups[0].config.group_name(), "only");
}

TEST(ExpandSweep, RejectsMalformedSweeps) {
  EXPECT_THROW((void)expand_sweep(json::parse(R"({"axes": {}})")), InvalidArgumentError);
  EXPECT_THROW((void)expand_sweep(json::parse(R"({"base": {}, "axes": {"w": []}})")),
               InvalidArgumentError);
  EXPECT_THROW((void)expand_sweep(json::parse(R"({"base": {}, "axis": {}})")),
               InvalidArgumentError);
  EXPECT_THROW((void)expand_sweep(json::parse(R"({"base": {"runs": 0}})")), InvalidArgumentError);
  EXPECT_THROW((void)expand_sweep(json::parse(R"({"base": {}, "axes": {"w": [2.0]}})")),
               InvalidArgumentError);
}

}  // namespace
}  // namespace twincal
