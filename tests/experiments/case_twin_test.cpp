#include "twincal/experiments/case_twin.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "twincal/core/error.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/experiments/scanned_assembly.hpp"
#include "twincal/models/locator_subset.hpp"
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

}  // namespace
}  // namespace twincal
