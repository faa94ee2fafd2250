#include "twincal/controllers/sensitivity_weights.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "controller_fixture.hpp"

namespace twincal {
namespace {

TEST(SensitivityWeights, AreTheCurvatureOfTheQualityAtTheOptimumScaledToMeanOne) {
  const RmsQuadraticTwin twin = test_support::make_twin(3);
  const IndividualOptimum<RmsQuadraticTwin> optimum(twin);
  const std::vector<AssemblyId> assemblies = twin.assemblies();
  const VectorX weights = sensitivity_weights(optimum, assemblies, {.step = 1e-3});
  // Q = sqrt(q0 + eᵀHe) curves by H_ii / sqrt(q0) along locator i at e = 0.
  VectorX expected = VectorX::Zero(3);
  for (const AssemblyId& x : assemblies) {
    expected += twin.curvature().diagonal() / twin.optimal_quality(x);
  }
  expected /= expected.mean();
  EXPECT_NEAR(weights.mean(), 1.0, 1e-12);
  EXPECT_LT((weights - expected).cwiseAbs().maxCoeff(), 1e-4);
}

TEST(SensitivityWeights, RejectBadInput) {
  const RmsQuadraticTwin twin = test_support::make_twin(2);
  const IndividualOptimum<RmsQuadraticTwin> optimum(twin);
  EXPECT_THAT([&] { (void)sensitivity_weights(optimum, {}); },
              ::testing::ThrowsMessage<InvalidArgumentError>(
                  "assemblies: is empty; rule: at least one assembly is needed"));
  EXPECT_THAT([&] { (void)sensitivity_weights(optimum, twin.assemblies(), {.step = 0.0}); },
              ::testing::ThrowsMessage<InvalidArgumentError>(
                  "SensitivityOptions: step: value is 0; rule: must be finite and > 0"));
}

}  // namespace
}  // namespace twincal
