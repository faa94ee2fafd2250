#include "twincal/controllers/constant_velocity_estimator.hpp"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "twincal/core/error.hpp"
#include "twincal/core/random_stream.hpp"

namespace twincal {
namespace {

// A known quadratic twin: Q²(x_t, v) = c_t + (v − u0_t)ᵀ H (v − u0_t), c_t and u0_t varying.
struct DriftScenario {
  QuadraticModel<3> model;
  RandomStream stream{7};

  DriftScenario() {
    model.center = Eigen::Vector3d::Zero();
    model.half_gradient = Eigen::Vector3d::Zero();
    model.hessian << 2.0, 0.3, 0.0, 0.3, 1.0, -0.2, 0.0, -0.2, 0.5;
  }

  // The model of assembly t and the control the estimator's user would apply: the estimate
  // plus a small known probe.
  Eigen::Vector3d next(Index t, const Eigen::Vector3d& estimate) {
    model.value = 0.3 + 0.1 * std::sin(static_cast<double>(t));
    model.center = Eigen::Vector3d(0.1 * std::cos(0.7 * static_cast<double>(t)), -0.05, 0.02);
    Eigen::Vector3d probe;
    stream.fill_normal(probe);
    return model.center + estimate + 0.02 * probe;
  }

  [[nodiscard]] double plant(const Eigen::Vector3d& control, const Eigen::Vector3d& offset) const {
    return std::sqrt(model(Eigen::Vector3d(control - offset)));
  }
};

ConstantVelocityEstimator<3> make_estimator() {
  return ConstantVelocityEstimator<3>(Eigen::Vector3d::Constant(2.0), 1e-4);
}

// With consistent (noiseless) data a constant-velocity drift is followed without lag: after 30
// assemblies the estimate is within 2 % of the 0.8 the offset travelled (what remains is the
// prior's pull, which the data outweigh as they accumulate), the velocity within 4 % of |v|.
TEST(ConstantVelocityEstimator, FollowsAConstantVelocityDriftWithoutLag) {
  DriftScenario scenario;
  ConstantVelocityEstimator<3> estimator = make_estimator();
  estimator.reset(0, Eigen::Vector3d::Zero());
  const Eigen::Vector3d velocity(0.01, -0.02, 0.015);
  for (Index t = 0; t < 30; ++t) {
    const Eigen::Vector3d offset = static_cast<double>(t) * velocity;
    const Eigen::Vector3d u = scenario.next(t, estimator.position());
    estimator.add(t, scenario.model, u, scenario.plant(u, offset));
    estimator.fit(t + 1);
  }
  EXPECT_LT((estimator.position() - 30.0 * velocity).norm(), 0.015);
  EXPECT_LT((estimator.state().tail(3) - velocity).norm(), 1e-3);
  EXPECT_EQ(estimator.changes(), 0);
  EXPECT_EQ(estimator.history_size(), 30);
  EXPECT_TRUE(estimator.significant());
  // The covariance is the inverse Gauss–Newton matrix: symmetric positive definite.
  EXPECT_TRUE(estimator.covariance().isApprox(estimator.covariance().transpose()));
  EXPECT_GT(estimator.covariance().ldlt().vectorD().minCoeff(), 0.0);
}

// The paper's drift turns back (eq. 15): the change is declared and the estimate recovers.
TEST(ConstantVelocityEstimator, DeclaresAReversalAndRecovers) {
  DriftScenario scenario;
  ConstantVelocityEstimator<3> estimator = make_estimator();
  estimator.reset(0, Eigen::Vector3d::Zero());
  const Eigen::Vector3d velocity(0.01, -0.02, 0.015);
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  Eigen::Vector3d step = velocity;
  for (Index t = 0; t < 60; ++t) {
    if (t == 25) step = -step;
    const Eigen::Vector3d u = scenario.next(t, estimator.position());
    estimator.add(t, scenario.model, u, scenario.plant(u, offset));
    offset += step;
    estimator.fit(t + 1);
  }
  EXPECT_GE(estimator.changes(), 1);
  EXPECT_LT((estimator.position() - offset).norm(), 0.03);
  EXPECT_LT((estimator.state().tail(3) + velocity).norm(), 2e-3);
}

// A quality that hardly depends on the offset (the whole drift moves z by far less than σz) does
// not show it: the estimate is not significant, so the controller does not correct with it.
TEST(ConstantVelocityEstimator, AnOffsetBelowTheNoiseIsNotSignificant) {
  DriftScenario scenario;
  scenario.model.hessian = Eigen::Matrix3d::Identity() * 1e-5;
  ConstantVelocityEstimator<3> estimator = make_estimator();
  estimator.reset(0, Eigen::Vector3d::Zero());
  const Eigen::Vector3d velocity(0.01, -0.02, 0.015);
  for (Index t = 0; t < 30; ++t) {
    const Eigen::Vector3d u = scenario.next(t, Eigen::Vector3d::Zero());
    estimator.add(t, scenario.model, u, scenario.plant(u, static_cast<double>(t) * velocity));
    estimator.fit(t + 1);
    EXPECT_FALSE(estimator.significant()) << "assembly " << t;
  }
}

// An assembly whose model errs (variance σz² + τ²) weighs less: the same error of its quality
// (2σz, below the change-of-velocity gate) moves the estimate less with τ = 5σz than with
// τ = 0, measured against the estimate from its correct quality.
TEST(ConstantVelocityEstimator, AnAssemblyWithAModelErrorWeighsLess) {
  const Eigen::Vector3d offset(0.2, -0.1, 0.05);
  const auto estimate = [&](double quality_error, double model_variance) {
    DriftScenario scenario;
    ConstantVelocityEstimator<3> estimator = make_estimator();
    estimator.reset(0, Eigen::Vector3d::Zero());
    for (Index t = 0; t < 12; ++t) {
      const Eigen::Vector3d u = scenario.next(t, estimator.position());
      estimator.add(t, scenario.model, u, scenario.plant(u, offset));
      estimator.fit(t + 1);
    }
    const Eigen::Vector3d u = scenario.next(12, estimator.position());
    estimator.add(12, scenario.model, u, scenario.plant(u, offset) + quality_error, model_variance);
    estimator.fit(13);
    EXPECT_EQ(estimator.changes(), 0);
    return Eigen::Vector3d(estimator.position());
  };
  const double exact = (estimate(0.02, 0.0) - estimate(0.0, 0.0)).norm();
  const double erring = (estimate(0.02, 25e-4) - estimate(0.0, 25e-4)).norm();
  EXPECT_GT(exact, 1e-3);
  EXPECT_LT(erring, 0.5 * exact);
}

TEST(ConstantVelocityEstimator, RefusesBadInputAndKeepsItsState) {
  DriftScenario scenario;
  ConstantVelocityEstimator<3> estimator = make_estimator();
  estimator.reset(0, Eigen::Vector3d(0.1, 0.0, 0.0));
  const Eigen::Vector3d u = scenario.next(0, estimator.position());
  estimator.add(0, scenario.model, u, 0.6);
  estimator.fit(1);
  const Eigen::Vector<double, 6> state = estimator.state();
  EXPECT_THROW(estimator.add(1, scenario.model, u, std::numeric_limits<double>::infinity()),
               NonFiniteError);
  EXPECT_THROW(estimator.add(-1, scenario.model, u, 0.6), InvalidArgumentError);
  EXPECT_THROW(estimator.reset(2, Eigen::Vector3d::Zero(), -Eigen::Matrix3d::Identity()),
               NotPositiveDefiniteError);
  EXPECT_THROW(estimator.add(1, scenario.model, u, 0.6, -1e-6), InvalidArgumentError);
  EXPECT_THROW(estimator.add(1, scenario.model, u, 0.6, std::nan("")), NonFiniteError);
  EXPECT_EQ(estimator.state(), state);
  EXPECT_EQ(estimator.history_size(), 1);
}

TEST(ConstantVelocityEstimator, OptionsNameTheRuleTheyBreak) {
  ConstantVelocityOptions inverted;
  inverted.change_window = 3;
  inverted.change_lag = 2;
  EXPECT_EQ(inverted.validate(),
            "change_window and change_lag are 3 and 2; rule: 1 <= change_window <= change_lag");
  EXPECT_EQ(ConstantVelocityOptions{.initial_position_fraction = 0.6}.validate(),
            "initial_position_fraction is 0.6; rule: finite, > 0 and <= position_fraction = 0.5");
  EXPECT_EQ(ConstantVelocityOptions{.max_history = 4}.validate(),
            "max_history is 4; rule: must be > change_lag = 6");
  EXPECT_THROW(ConstantVelocityEstimator<3>(Eigen::Vector3d(2.0, 0.0, 2.0), 1e-4),
               InvalidArgumentError);
  EXPECT_THROW(ConstantVelocityEstimator<3>(Eigen::Vector3d::Constant(2.0), 0.0),
               InvalidArgumentError);
}

}  // namespace
}  // namespace twincal
