#include "twincal/controllers/active/quadratic_moments.hpp"

#include <cmath>

#include <gtest/gtest.h>

#include "twincal/core/random_stream.hpp"

namespace twincal {
namespace {

// A random quadratic model, offset prior and control in d = 3.
struct MomentsCase {
  QuadraticModel<3> model;
  Vector<3> control;
  Vector<3> mean;
  SquareMatrix<3> covariance;
};

MomentsCase moments_case() {
  RandomStream stream(11);
  MomentsCase c;
  Eigen::Matrix3d a;
  stream.fill_normal(a);
  c.model.hessian = a * a.transpose() + Eigen::Matrix3d::Identity();
  c.model.center = Eigen::Vector3d(0.1, -0.2, 0.05);
  c.model.value = 0.3;
  c.model.half_gradient = Eigen::Vector3d(0.2, -0.1, 0.3);
  c.control = Eigen::Vector3d(0.4, 0.1, -0.3);
  c.mean = Eigen::Vector3d(0.05, -0.1, 0.2);
  Eigen::Matrix3d b;
  stream.fill_normal(b);
  c.covariance = 0.02 * (b * b.transpose()) + 0.01 * Eigen::Matrix3d::Identity();
  return c;
}

TEST(QuadraticMoments, MatchMonteCarloOfTheSquaredQualityWithinItsStandardError) {
  const MomentsCase c = moments_case();
  QuadraticMomentsWorkspace<3> work;
  QuadraticMeasurementMoments<3> exact;
  quadratic_measurement_moments(c.model, c.control, c.mean, c.covariance, work, exact);

  RandomStream stream(12);
  const Eigen::Matrix3d lower = c.covariance.llt().matrixL();
  constexpr int samples = 400000;
  double sum = 0.0;
  double sum2 = 0.0;
  Eigen::Vector3d cross = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal;
  for (int i = 0; i < samples; ++i) {
    stream.fill_normal(normal);
    const Eigen::Vector3d offset = c.mean + lower * normal;
    const Eigen::Vector3d v = c.control - offset;
    const double h = c.model(v);
    sum += h;
    sum2 += h * h;
    cross += (offset - c.mean) * h;
  }
  const double mean = sum / samples;
  const double variance = sum2 / samples - mean * mean;
  const double standard_error = std::sqrt(variance / samples);
  EXPECT_NEAR(exact.mean, mean, 5.0 * standard_error);
  // Var of a sample variance ≈ (μ4 − σ⁴)/n; 3σ²·sqrt(2/n) bounds it generously here.
  EXPECT_NEAR(exact.variance, variance, 5.0 * variance * std::sqrt(2.0 / samples) * 3.0);
  const Eigen::Vector3d cross_mc = cross / samples;
  for (int k = 0; k < 3; ++k) {
    const double spread = std::sqrt(c.covariance(k, k) * variance / samples);
    EXPECT_NEAR(exact.cross_covariance(k), cross_mc(k), 5.0 * spread) << "component " << k;
  }
}

TEST(QuadraticMoments, ReduceToTheModelAtAPointMassPrior) {
  const MomentsCase c = moments_case();
  QuadraticMomentsWorkspace<Dynamic> work;
  work.resize(3);
  QuadraticMeasurementMoments<Dynamic> exact;
  exact.cross_covariance.resize(3);
  QuadraticModel<Dynamic> model{c.model.center, c.model.value, c.model.half_gradient,
                                c.model.hessian};
  const VectorX control = c.control;
  const VectorX mean = c.mean;
  const MatrixX zero = MatrixX::Zero(3, 3);
  quadratic_measurement_moments(model, control, mean, zero, work, exact);
  EXPECT_DOUBLE_EQ(exact.mean, c.model(Eigen::Vector3d(c.control - c.mean)));
  EXPECT_EQ(exact.variance, 0.0);
  EXPECT_EQ(exact.cross_covariance, VectorX::Zero(3));
}

}  // namespace
}  // namespace twincal
