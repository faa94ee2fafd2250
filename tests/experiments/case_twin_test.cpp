#include "twincal/experiments/case_twin.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "twincal/core/error.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/experiments/scanned_assembly.hpp"
#include "twincal/models/key_point_twin.hpp"
#include "twincal/models/locator_subset.hpp"
#include "twincal/models/no_nonlinearity.hpp"
#include "twincal/models/rms_quadratic_twin.hpp"

namespace twincal {
namespace {

RmsQuadraticTwin case_twin_reference(Index d) {
  RmsQuadraticTwinOptions options;
  options.assemblies.dimension = d;
  return RmsQuadraticTwin::generate(options, RandomStream(11));
}

AnyTwin case_twin_erased(const RmsQuadraticTwin& twin) {
  return {twin, twin.assemblies(), {0, 1, 2}};
}

TEST(CaseTwin, AgreesWithModelsLocatorSubset) {
  const RmsQuadraticTwin full = case_twin_reference(5);
  const CaseTwin twin(case_twin_erased(full), {3, 1});
  const LocatorSubset<RmsQuadraticTwin> reference(full, {3, 1});
  EXPECT_EQ(twin.control_dimension(), 2);
  EXPECT_EQ(twin.locator_names(), reference.locator_names());
  EXPECT_EQ(twin.lower_bounds(), reference.lower_bounds());
  Eigen::MatrixXd controls(2, 3);
  controls << 0.1, -0.2, 0.05, 0.3, 0.0, -0.15;
  Eigen::VectorXd values(3);
  Eigen::VectorXd expected(3);
  for (const AssemblyId& x : {AssemblyId{0, 0}, AssemblyId{7, 3}, AssemblyId{9, 9}}) {
    EXPECT_EQ(twin.optimum(x), reference.optimum(x));
    EXPECT_EQ(twin.optimal_quality(x), reference.optimal_quality(x));
    twin.quality_batch(x, controls, values);
    reference.quality_batch(x, controls, expected);
    EXPECT_EQ(values, expected);
    const Eigen::VectorXd u = controls.col(1);
    EXPECT_EQ(twin.quality(x, u), reference.quality(x, u));
    EXPECT_EQ(twin.plant_quality(x, u), reference.quality(x, u));
  }
}

TEST(CaseTwin, CountsEvaluationsButNotThePlants) {
  const RmsQuadraticTwin full = case_twin_reference(3);
  const CaseTwin twin(case_twin_erased(full), {0});
  const std::uint64_t before = CaseTwin::evaluations_on_this_thread();
  const Eigen::VectorXd u = Eigen::VectorXd::Constant(1, 0.1);
  (void)twin.quality({1, 1}, u);
  Eigen::VectorXd out(4);
  twin.quality_batch({1, 1}, Eigen::MatrixXd::Zero(1, 4), out);
  (void)twin.plant_quality({1, 1}, u);
  EXPECT_EQ(CaseTwin::evaluations_on_this_thread() - before, 5U);
}

// The deviations at the controlled locators, the others at u0(x), as the full twin gives them
// for the embedded control; counted as Q-evaluations. A twin that answers only Q has none.
TEST(CaseTwin, AnswersTheKeyPointsDeviationsOfItsFullTwin) {
  KeyPointTwinOptions options;
  options.assemblies.dimension = 4;
  const KeyPointTwin<NoNonlinearity> full(options, RandomStream(3));
  const CaseTwin twin(AnyTwin(full, full.assemblies(), {0, 1, 2, 3}), {2, 0});
  ASSERT_EQ(twin.key_point_count(), full.key_point_count());
  const AssemblyId x{2, 5};
  Eigen::MatrixXd controls(2, 3);
  controls << 0.1, -0.2, 0.05, 0.3, 0.0, -0.15;
  Eigen::MatrixXd deviations(full.key_point_count(), 3);
  const std::uint64_t before = CaseTwin::evaluations_on_this_thread();
  twin.deviations_batch(x, controls, deviations);
  EXPECT_EQ(CaseTwin::evaluations_on_this_thread() - before, 3U);
  Eigen::MatrixXd embedded = full.optimum(x).replicate(1, 3);
  embedded.row(2) = controls.row(0);
  embedded.row(0) = controls.row(1);
  Eigen::MatrixXd expected(full.key_point_count(), 3);
  full.deviations_batch(x, embedded, expected);
  EXPECT_EQ(deviations, expected);
  Eigen::MatrixXd wrong(full.key_point_count() + 1, 3);
  EXPECT_THROW(twin.deviations_batch(x, controls, wrong), DimensionMismatchError);

  const RmsQuadraticTwin quality_only = case_twin_reference(3);
  const CaseTwin without(case_twin_erased(quality_only), {1});
  EXPECT_EQ(without.key_point_count(), 0);
  Eigen::MatrixXd none(0, 1);
  EXPECT_THROW(without.deviations_batch({0, 0}, Eigen::MatrixXd::Zero(1, 1), none),
               InvalidArgumentError);
}

TEST(CaseTwin, RejectsBadLocatorsAndUnknownAssemblies) {
  const RmsQuadraticTwin full = case_twin_reference(3);
  EXPECT_THROW(CaseTwin(case_twin_erased(full), {}), InvalidArgumentError);
  EXPECT_THROW(CaseTwin(case_twin_erased(full), {3}), InvalidArgumentError);
  EXPECT_THROW(CaseTwin(case_twin_erased(full), {1, 1}), InvalidArgumentError);
  const CaseTwin twin(case_twin_erased(full), {2});
  EXPECT_THROW((void)twin.optimal_quality({10, 0}), InvalidArgumentError);
  EXPECT_THROW((void)twin.optimum({0, -1}), InvalidArgumentError);
}

TEST(CaseTwin, RefusesScannedPartsWhenItsTwinTakesNone) {
  const RmsQuadraticTwin full = case_twin_reference(3);
  CaseTwin twin(case_twin_erased(full), {0, 2});
  try {
    (void)twin.add_scanned(nlohmann::json{{"upper", {1.0}}});
    FAIL() << "scanned parts were accepted by a twin that takes none";
  } catch (const InvalidArgumentError& error) {
    EXPECT_EQ(error.argument(), "parts");
  }
  EXPECT_THROW((void)twin.optimum(scanned_assembly(0)), InvalidArgumentError);
}

// A plant other than the twin (Assumption 1 broken): the controllers' calls see the twin, the
// plant's calls the plant, both at the same full controls (the uncontrolled locators at the
// twin's u0); residuals are measured against the plant's own optimum.
TEST(CaseTwin, MeasuresASeparatePlantWhereTheControllersSeeTheTwin) {
  const RmsQuadraticTwin full = case_twin_reference(3);
  RmsQuadraticTwinOptions other_options;
  other_options.assemblies.dimension = 3;
  const RmsQuadraticTwin other = RmsQuadraticTwin::generate(other_options, RandomStream(12));
  const CaseTwin twin(case_twin_erased(full), {0, 2}, case_twin_erased(other));
  EXPECT_TRUE(twin.separate_plant());
  const AssemblyId x{4, 6};
  Eigen::VectorXd u(2);
  u << 0.1, -0.3;
  Eigen::VectorXd embedded = full.optimum(x);
  embedded(0) = u(0);
  embedded(2) = u(1);
  EXPECT_EQ(twin.quality(x, u), full.quality(x, embedded));
  EXPECT_EQ(twin.plant_quality(x, u), other.quality(x, embedded));
  EXPECT_NE(twin.quality(x, u), twin.plant_quality(x, u));
  EXPECT_EQ(twin.optimal_quality(x), full.optimal_quality(x));
  EXPECT_EQ(twin.plant_optimal_quality(x), other.optimal_quality(x));
  const CaseTwin same(case_twin_erased(full), {0, 2});
  EXPECT_FALSE(same.separate_plant());
  EXPECT_EQ(same.plant_optimal_quality(x), same.optimal_quality(x));
}

TEST(CaseTwin, RefusesAPlantWithOtherLocatorsAndScannedPartsWithAPlant) {
  const RmsQuadraticTwin full = case_twin_reference(3);
  try {
    const CaseTwin twin(case_twin_erased(full), {0}, case_twin_erased(case_twin_reference(4)));
    FAIL() << "a plant of 4 locators was accepted behind a twin of 3";
  } catch (const InvalidArgumentError& error) {
    EXPECT_EQ(error.argument(), "plant");
  }
  CaseTwin twin(case_twin_erased(full), {0}, case_twin_erased(full));
  EXPECT_THROW((void)twin.add_scanned(nlohmann::json{{"upper", {1.0}}}), InvalidArgumentError);
}

TEST(CaseTwin, QuadraticDepartureIsZeroForAQuadraticTwin) {
  const CaseTwin twin(case_twin_erased(case_twin_reference(3)), {0, 1, 2});
  const std::uint64_t before = CaseTwin::evaluations_on_this_thread();
  EXPECT_LT(median_quadratic_departure(twin, 3), 1e-9);
  EXPECT_EQ(CaseTwin::evaluations_on_this_thread(), before) << "not a controller's evaluations";
}

}  // namespace
}  // namespace twincal
