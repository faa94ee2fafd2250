#include "twincal/controllers/active/thompson_probe.hpp"

#include <gtest/gtest.h>

#include "twincal/core/error.hpp"

namespace twincal {
namespace {

static_assert(ProbeDesign<ThompsonProbe<3>, 3>);
static_assert(ProbeDesign<ThompsonProbe<Dynamic>, Dynamic>);

struct ThompsonSetting {
  Eigen::Matrix3d hessian = Eigen::Matrix3d::Identity();
  Eigen::Vector3d gradient = Eigen::Vector3d::Zero();
  Eigen::Matrix3d covariance;
  Eigen::Vector3d max_probe = Eigen::Vector3d::Constant(10.0);

  ThompsonSetting() { covariance << 4.0, 1.0, 0.0, 1.0, 2.0, 0.5, 0.0, 0.5, 1.0; }
  [[nodiscard]] ProbeContext<3> context() const {
    return ProbeContext<3>{hessian, gradient, covariance, 1.0, 1e-4, 1.0, max_probe};
  }
};

// The probes are draws from N(0, s² P): their sample covariance converges to it.
TEST(ThompsonProbe, DrawsFromTheScaledPosterior) {
  const ThompsonSetting setting;
  ThompsonProbe<3> design(0.5, RandomStream(11));
  const int draws = 200000;
  Eigen::Matrix3d second = Eigen::Matrix3d::Zero();
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  Eigen::Vector3d probe;
  for (int i = 0; i < draws; ++i) {
    design.design(setting.context(), probe);
    mean += probe;
    second += probe * probe.transpose();
  }
  mean /= draws;
  second /= draws;
  EXPECT_LT(mean.norm(), 0.02);
  // Standard error of each entry ≈ s²·sqrt(2·P_ii P_jj / draws) < 0.005.
  EXPECT_LT((second - 0.25 * setting.covariance).cwiseAbs().maxCoeff(), 0.02);
}

TEST(ThompsonProbe, ClipsToTheLargestProbeAndIsReproducible) {
  ThompsonSetting setting;
  setting.max_probe = Eigen::Vector3d::Constant(0.01);
  ThompsonProbe<Dynamic> first(1.0, RandomStream(3));
  ThompsonProbe<Dynamic> second(1.0, RandomStream(5));
  second.reseed(RandomStream(3));
  const MatrixX hessian = setting.hessian;
  const VectorX gradient = setting.gradient;
  const MatrixX covariance = setting.covariance;
  const VectorX max_probe = setting.max_probe;
  const ProbeContext<Dynamic> context{hessian, gradient, covariance, 1.0, 1e-4, 1.0, max_probe};
  VectorX a;
  VectorX b;
  for (int i = 0; i < 10; ++i) {
    first.design(context, a);
    second.design(context, b);
    EXPECT_EQ(a, b);
    EXPECT_LE(a.cwiseAbs().maxCoeff(), 0.01);
  }
}

TEST(ThompsonProbe, RefusesAScaleOutsideItsRange) {
  EXPECT_THROW(ThompsonProbe<3>(0.0), InvalidArgumentError);
  EXPECT_THROW(ThompsonProbe<3>(1.5), InvalidArgumentError);
}

}  // namespace
}  // namespace twincal
