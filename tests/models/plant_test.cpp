#include "twincal/models/plant.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "twincal/core/random_stream.hpp"
#include "twincal/models/bouncing_drift.hpp"
#include "twincal/models/constant_drift.hpp"
#include "twincal/models/rms_quadratic_twin.hpp"

namespace twincal {
namespace {

RmsQuadraticTwin make_plant_twin() {
  RmsQuadraticTwinOptions options;
  options.assemblies.dimension = 2;
  return RmsQuadraticTwin::generate(options, RandomStream(31));
}

TEST(Plant, ProducesWithTheDriftingOffsetAndNoNoise) {
  const RmsQuadraticTwin twin = make_plant_twin();
  BouncingDrift<2> drift(Eigen::Vector2d(0.03, -0.02), Eigen::Vector2d(0.5, 0.5));
  Plant plant(twin, drift, 0.0, RandomStream(1));
  const AssemblyId x{2, 3};
  const Eigen::Vector2d u(0.1, 0.1);
  for (Index t = 0; t < 5; ++t) {
    EXPECT_EQ(plant.time(), t);
    EXPECT_EQ(plant.offset(), drift.offset());
    // eq. (5b) without noise: z_t = Q(x, u − δu*_t).
    EXPECT_EQ(plant.produce(x, u), twin.quality(x, u - drift.offset()));
    drift.advance();
  }
  // Applying u0(x) + δu*_t reaches the optimum (eq. 7).
  const Eigen::Vector2d ideal = twin.optimum(x) + plant.offset();
  EXPECT_NEAR(plant.produce(x, ideal), twin.optimal_quality(x), 1e-15);
}

TEST(Plant, AddsSeededGaussianNoise) {
  const RmsQuadraticTwin twin = make_plant_twin();
  const ConstantDrift<Dynamic> drift(VectorX::Constant(2, 0.05));
  Plant plant(twin, drift, 1e-4, RandomStream(7));
  Plant replay(twin, drift, 1e-4, RandomStream(7));
  const AssemblyId x{0, 0};
  const VectorX u = VectorX::Zero(2);
  const double truth = plant.noiseless_quality(x, u);
  constexpr int kSamples = 20000;
  double sum = 0.0;
  double sum_sq = 0.0;
  for (int i = 0; i < kSamples; ++i) {
    const double z = plant.produce(x, u);
    EXPECT_EQ(z, replay.produce(x, u));
    sum += z - truth;
    sum_sq += (z - truth) * (z - truth);
  }
  // Mean within 5 standard errors (5·0.01/sqrt(n)), variance within 5·sqrt(2/n) relative.
  EXPECT_LT(std::abs(sum / kSamples), 5.0 * 0.01 / std::sqrt(kSamples));
  EXPECT_NEAR(sum_sq / kSamples, 1e-4, 5.0 * std::sqrt(2.0 / kSamples) * 1e-4);
}

TEST(Plant, RejectsMismatchedDriftAndBadNoise) {
  const RmsQuadraticTwin twin = make_plant_twin();
  EXPECT_THAT(
      [&] { (void)Plant(twin, ConstantDrift<3>(Eigen::Vector3d::Zero()), 0.0, RandomStream(1)); },
      ::testing::ThrowsMessage<DimensionMismatchError>(
          "drift.dimension(): size is 3; rule: must equal 2"));
  EXPECT_THAT(
      [&] { (void)Plant(twin, ConstantDrift<2>(Eigen::Vector2d::Zero()), -1.0, RandomStream(1)); },
      ::testing::ThrowsMessage<InvalidArgumentError>(
          "noise_variance: value is -1; rule: must be >= 0"));
  Plant plant(twin, ConstantDrift<2>(Eigen::Vector2d::Zero()), 0.0, RandomStream(1));
  EXPECT_THROW((void)plant.produce({0, 0}, VectorX::Zero(3)), DimensionMismatchError);
  EXPECT_EQ(plant.time(), 0);  // a failed production changes nothing
}

}  // namespace
}  // namespace twincal
