#include "twincal/controllers/active/information_probe.hpp"

#include <cmath>

#include <gtest/gtest.h>

namespace twincal {
namespace {

// With g = 0 and diagonal H and P, the best axis is the locator with the largest H_ii P_ii, and
// the best amplitude along it minimizes the design's objective, cost(a) − T·gain(a), written
// out below from its definition and minimized by brute force.
TEST(InformationProbe, ProbesTheMostCostlyUncertainAxisWithTheClosedFormAmplitude) {
  const Eigen::Matrix3d hessian = Eigen::Vector3d(0.2, 0.1, 0.05).asDiagonal();
  const Eigen::Matrix3d covariance = Eigen::Vector3d(0.001, 0.01, 0.002).asDiagonal();
  const Eigen::Vector3d gradient = Eigen::Vector3d::Zero();
  const Eigen::Vector3d max_probe = Eigen::Vector3d::Constant(0.5);
  const double value = 0.0036;
  const double sigma2 = 1e-4;
  const double horizon = 20.0;
  const ProbeContext<3> context{hessian, gradient, covariance, value, sigma2, horizon, max_probe};
  InformationProbe<3> design;
  Eigen::Vector3d probe;
  design.design(context, probe);

  // H P is largest on locator 1 (0.1 · 0.01): the probe is along e_1.
  EXPECT_EQ(probe(0), 0.0);
  EXPECT_EQ(probe(2), 0.0);
  const double trace_hp = (hessian * covariance).trace();
  const double trace_hphp = (hessian * covariance * hessian * covariance).trace();
  const auto objective = [&](double p) {
    const double cost = hessian(1, 1) * p * p;
    const double b = -2.0 * hessian(1, 1) * p;
    const double r = 4.0 * (value + cost + trace_hp) * sigma2 + 2.0 * sigma2 * sigma2;
    const double gain = b * covariance(1, 1) * hessian(1, 1) * covariance(1, 1) * b /
                        (b * covariance(1, 1) * b + 2.0 * trace_hphp + r);
    return cost - horizon * gain;
  };
  double best = 0.0;
  for (double p = 0.0; p <= 0.5; p += 1e-5) {
    if (objective(p) < objective(best)) best = p;
  }
  ASSERT_GT(best, 0.0);
  // The design's amplitude grid has ratio 0.8: within one grid step of the optimum.
  EXPECT_NEAR(std::abs(probe(1)), best, 0.25 * best);
  EXPECT_LE(objective(std::abs(probe(1))), objective(0.0));
}

TEST(InformationProbe, DoesNotProbeWhenInformationIsWorthNothingOrTheQualityIgnoresTheOffset) {
  const Eigen::Matrix2d hessian = Eigen::Vector2d(0.2, 0.1).asDiagonal();
  const Eigen::Matrix2d covariance = Eigen::Matrix2d::Identity() * 1e-3;
  const Eigen::Vector2d gradient = Eigen::Vector2d::Zero();
  const Eigen::Vector2d max_probe = Eigen::Vector2d::Constant(0.5);
  InformationProbe<2> design;
  Eigen::Vector2d probe;
  design.design(ProbeContext<2>{hessian, gradient, covariance, 0.01, 1e-4, 0.0, max_probe}, probe);
  EXPECT_EQ(probe, Eigen::Vector2d::Zero());  // horizon 0: information is worth nothing
  const Eigen::Matrix2d flat = Eigen::Matrix2d::Zero();
  design.design(ProbeContext<2>{flat, gradient, covariance, 0.01, 1e-4, 50.0, max_probe}, probe);
  EXPECT_EQ(probe, Eigen::Vector2d::Zero());  // H = 0: nothing to learn
}

TEST(InformationProbe, AlternatesTheSignOfEqualProbes) {
  const Eigen::Matrix2d hessian = Eigen::Vector2d(0.2, 0.1).asDiagonal();
  const Eigen::Matrix2d covariance = Eigen::Matrix2d::Identity() * 1e-2;
  const Eigen::Vector2d gradient = Eigen::Vector2d::Zero();
  const Eigen::Vector2d max_probe = Eigen::Vector2d::Constant(0.5);
  const MatrixX h = hessian;
  const VectorX g = gradient;
  const MatrixX p = covariance;
  const VectorX reach = max_probe;
  const ProbeContext<Dynamic> context{h, g, p, 0.01, 1e-4, 30.0, reach};
  InformationProbe<Dynamic> design;
  VectorX first(2);
  VectorX second(2);
  design.design(context, first);
  design.design(context, second);
  ASSERT_GT(first.norm(), 0.0);
  EXPECT_LT((first + second).norm(), 1e-15);
}

}  // namespace
}  // namespace twincal
