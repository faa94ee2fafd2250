#include "twincal/experiments/twin_cases.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include <gtest/gtest.h>

#include "twincal/core/error.hpp"
#include "twincal/core/random_stream.hpp"

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

TEST(TwinCases, SheetMetalCasesAreTheFemTwin) {
  ExperimentConfig config;
  config.twin_case = TwinCase::door;
  config.locators = "ABC";
  const CaseTwin door = make_case_twin(config);
  EXPECT_EQ(door.full_twin().control_dimension(), 19);
  EXPECT_EQ(door.control_dimension(), 3);
  EXPECT_EQ(door.assemblies().size(), 100U);
  config.twin_case = TwinCase::body;
  EXPECT_EQ(make_case_twin(config).full_twin().control_dimension(), 12);
}

TEST(TwinCases, ContactCasesAreTheFemCasesWithContact) {
  EXPECT_EQ(parse_enum<TwinCase>("body-contact", "case"), TwinCase::body_contact);
  EXPECT_EQ(to_string(TwinCase::door_contact), "door-contact");
  for (const auto& [contact_case, linear_case] :
       {std::pair{TwinCase::body_contact, TwinCase::body},
        std::pair{TwinCase::door_contact, TwinCase::door}}) {
    ExperimentConfig config;
    config.twin_case = contact_case;
    const AnyTwin contact = make_twin(config);
    config.twin_case = linear_case;
    const AnyTwin linear = make_twin(config);
    // The same parts, locators and A, B, C ...
    EXPECT_EQ(contact.locator_names(), linear.locator_names());
    EXPECT_EQ(contact.assemblies(), linear.assemblies());
    EXPECT_EQ(contact.significant_locators(), linear.significant_locators());
    // ... and a different Q somewhere in the box.
    const Index d = contact.control_dimension();
    RandomStream stream(8);
    MatrixX controls(d, 32);
    for (double& v : controls.reshaped()) v = 2.0 * stream.uniform() - 1.0;
    VectorX with_contact(32);
    VectorX without(32);
    const AssemblyId x{0, 0};
    contact.quality_batch(x, controls, with_contact);
    linear.quality_batch(x, controls, without);
    EXPECT_GT((with_contact - without).cwiseAbs().maxCoeff(), 1e-4);
    // The searched optimum is at least as good as the linear one on the contact twin.
    EXPECT_LE(contact.optimal_quality(x), contact.quality(x, linear.optimum(x)));
  }
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

TEST(TwinCases, AnalyticNonlinearitiesAreKeyPointTwinsWithSearchedOptima) {
  ExperimentConfig config = twin_cases_analytic(3);
  config.locators = "all";
  const CaseTwin quadratic = make_case_twin(config);
  config.nonlinearity = Nonlinearity::stiffening;
  const CaseTwin stiffening = make_case_twin(config);
  const AssemblyId x{3, 4};
  EXPECT_NE(stiffening.optimum(x), quadratic.optimum(x));
  EXPECT_LE(stiffening.optimal_quality(x), stiffening.quality(x, quadratic.optimum(x)));
  EXPECT_GT(median_quadratic_departure(stiffening, 3), 0.02);
  EXPECT_LT(median_quadratic_departure(quadratic, 3), 1e-9);
  EXPECT_FALSE(stiffening.separate_plant());
}

// The plant with a nonlinearity the twin lacks: the twin is the key-point twin without it, the
// plant the same twin with it; groups that differ only in the plant share the twin.
TEST(TwinCases, APlantWithANonlinearityTheTwinLacks) {
  ExperimentConfig config = twin_cases_analytic(3);
  config.locators = "all";
  config.plant_nonlinearity = Nonlinearity::contact;
  config.plant_strength = 0.75;
  ASSERT_TRUE(make_plant(config).has_value());
  EXPECT_FALSE(make_plant(twin_cases_analytic(3)).has_value());
  const CaseTwin twin = make_case_twin(config);
  ASSERT_TRUE(twin.separate_plant());
  RandomStream stream(5);
  MatrixX controls(3, 16);
  for (double& v : controls.reshaped()) v = 2.0 * stream.uniform() - 1.0;
  double largest = 0.0;
  const AssemblyId x{2, 7};
  for (Index j = 0; j < controls.cols(); ++j) {
    const VectorX u = controls.col(j);
    largest = std::max(largest, std::abs(twin.plant_quality(x, u) - twin.quality(x, u)));
  }
  EXPECT_GT(largest, 1e-4) << "the plant's contact shows somewhere in the box";
  // At the twin's optimum no contact has closed, so the plant agrees there.
  EXPECT_NEAR(twin.plant_quality(x, twin.optimum(x)), twin.optimal_quality(x), 1e-12);
  EXPECT_LE(twin.plant_optimal_quality(x), twin.optimal_quality(x) + 1e-9);

  std::vector<ExperimentGroup> groups(2);
  groups[0].config = config;
  groups[1].config = config;
  groups[1].config.plant_strength = 0.25;
  const std::vector<CaseTwin> twins = make_case_twins(groups);
  EXPECT_EQ(&twins[0].full_twin().locator_names(), &twins[1].full_twin().locator_names());
  const VectorX u = VectorX::Constant(3, 0.8);
  EXPECT_NE(twins[0].plant_quality(x, u), twins[1].plant_quality(x, u));
}

}  // namespace
}  // namespace twincal
