#include "twincal/experiments/twin_cases.hpp"

#include <gtest/gtest.h>

#include "twincal/core/error.hpp"

namespace twincal {
namespace {

ExperimentConfig twin_cases_analytic(Index d) {
  ExperimentConfig config;
  config.twin_case = TwinCase::analytic;
  config.analytic_dimension = d;
  return config;
}

TEST(TwinCases, AnalyticTwinNamesItsLocatorsByLetter) {
  const AnyTwin twin = make_twin(twin_cases_analytic(4));
  EXPECT_EQ(twin.control_dimension(), 4);
  EXPECT_EQ(twin.locator_names(), (std::vector<std::string>{"A", "B", "C", "D"}));
  EXPECT_EQ(twin.assemblies().size(), 100U);
  EXPECT_EQ(twin.significant_locators(), (std::vector<Index>{0, 1, 2}));
}

TEST(TwinCases, ResolvesLocatorSets) {
  const AnyTwin twin = make_twin(twin_cases_analytic(5));
  EXPECT_EQ(resolve_locators(twin, "B"), (std::vector<Index>{1}));
  EXPECT_EQ(resolve_locators(twin, "ABC"), (std::vector<Index>{0, 1, 2}));
  EXPECT_EQ(resolve_locators(twin, "all"), (std::vector<Index>{0, 1, 2, 3, 4}));
  EXPECT_EQ(resolve_locators(twin, "E,0,D"), (std::vector<Index>{4, 0, 3}));
  EXPECT_THROW((void)resolve_locators(twin, "Z"), InvalidArgumentError);
  EXPECT_THROW((void)resolve_locators(twin, "5"), InvalidArgumentError);
  EXPECT_THROW((void)resolve_locators(twin, "A,,B"), InvalidArgumentError);
  const AnyTwin small = make_twin(twin_cases_analytic(2));
  EXPECT_THROW((void)resolve_locators(small, "ABC"), InvalidArgumentError);
}

TEST(TwinCases, TheTwinSeedDecidesTheTwin) {
  ExperimentConfig a = twin_cases_analytic(3);
  ExperimentConfig b = a;
  b.twin_seed = a.twin_seed + 1;
  const AssemblyId x{2, 5};
  EXPECT_EQ(make_twin(a).optimal_quality(x), make_twin(a).optimal_quality(x));
  EXPECT_NE(make_twin(a).optimal_quality(x), make_twin(b).optimal_quality(x));
}

TEST(TwinCases, SheetMetalCasesAreTheFemTwinWhenItIsBuilt) {
  ExperimentConfig config;
  config.twin_case = TwinCase::door;
  config.locators = "ABC";
  if (!sheet_metal_cases_available()) {
    EXPECT_THROW((void)make_case_twin(config), InvalidArgumentError);
    return;
  }
  const CaseTwin door = make_case_twin(config);
  EXPECT_EQ(door.full_twin().control_dimension(), 19);
  EXPECT_EQ(door.control_dimension(), 3);
  EXPECT_EQ(door.assemblies().size(), 100U);
  config.twin_case = TwinCase::body;
  EXPECT_EQ(make_case_twin(config).full_twin().control_dimension(), 12);
}

TEST(TwinCases, GroupsOfOneTwinShareIt) {
  std::vector<ExperimentGroup> groups(3);
  groups[0].config = twin_cases_analytic(3);
  groups[1].config = twin_cases_analytic(3);
  groups[1].config.locators = "ABC";
  groups[2].config = twin_cases_analytic(4);
  const std::vector<CaseTwin> twins = make_case_twins(groups);
  ASSERT_EQ(twins.size(), 3U);
  EXPECT_EQ(twins[0].locators(), (std::vector<Index>{0}));
  EXPECT_EQ(twins[1].locators(), (std::vector<Index>{0, 1, 2}));
  EXPECT_EQ(&twins[0].full_twin().locator_names(), &twins[1].full_twin().locator_names());
  EXPECT_NE(&twins[0].full_twin().locator_names(), &twins[2].full_twin().locator_names());
  EXPECT_EQ(twins[2].full_twin().control_dimension(), 4);
}

}  // namespace
}  // namespace twincal
