// AnyController forwards to the controller it wraps: the same controls, estimates, covariances
// and snapshots, at a fixed size and at a run-time size, and the stated defaults for a
// controller that does not estimate.
#include "twincal/controllers/any_controller.hpp"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "controller_fixture.hpp"
#include "twincal/controllers/individualized_controller.hpp"
#include "twincal/controllers/presets.hpp"
#include "twincal/core/random_stream.hpp"

namespace twincal {
namespace {

using test_support::AnalyticTwin;
using test_support::make_twin;

// The assemblies both controllers see; the plant is the twin at an offset control.
std::vector<AssemblyId> any_controller_assemblies() {
  return {AssemblyId{0, 1}, AssemblyId{3, 4}, AssemblyId{7, 2},
          AssemblyId{5, 5}, AssemblyId{9, 0}, AssemblyId{2, 8}};
}

template <int N>
void expect_forwards_to_the_wrapped_controller(Index d) {
  const AnalyticTwin twin = make_twin(d);
  const RandomStream stream(11);
  PaperController<AnalyticTwin, N> direct = make_paper_controller<N>(twin, stream);
  AnyController any(make_paper_controller<N>(twin, stream), d);
  EXPECT_EQ(any.control_dimension(), d);
  EXPECT_TRUE(any.estimates());
  const VectorX offset = VectorX::Constant(d, 0.05);
  VectorX control(d);
  VectorX estimate(d);
  MatrixX covariance(d, d);
  for (const AssemblyId& x : any_controller_assemblies()) {
    const Vector<N> expected = direct.propose(x);
    any.propose(x, control);
    EXPECT_EQ(control, VectorX(expected));
    const double z = twin.quality(x, VectorX(control - offset));
    direct.observe(x, expected, z);
    any.observe(x, control, z);
    any.offset_estimate(estimate);
    any.offset_covariance(covariance);
    EXPECT_EQ(estimate, VectorX(direct.offset_estimate()));
    EXPECT_EQ(covariance, MatrixX(direct.offset_covariance()));
    EXPECT_EQ(any.offset_covariance_trace(), direct.offset_covariance().trace());
  }
  EXPECT_EQ(any.save(), direct.save());
  // A restored AnyController goes on as the direct one.
  AnyController restored(make_paper_controller<N>(twin, stream), d);
  restored.restore(nlohmann::json::parse(any.save().dump()));
  const AssemblyId next{4, 6};
  restored.propose(next, control);
  EXPECT_EQ(control, VectorX(direct.propose(next)));
}

TEST(AnyController, ForwardsToAFixedSizeController) {
  expect_forwards_to_the_wrapped_controller<3>(3);
}

TEST(AnyController, ForwardsToARunTimeSizedController) {
  expect_forwards_to_the_wrapped_controller<Dynamic>(2);
}

TEST(AnyController, AControllerThatDoesNotEstimateReportsZeroAndNaN) {
  const AnalyticTwin twin = make_twin(2);
  AnyController any(IndividualizedController<AnalyticTwin>(twin), 2);
  EXPECT_FALSE(any.estimates());
  const AssemblyId x{1, 1};
  VectorX control(2);
  any.propose(x, control);
  EXPECT_EQ(control, twin.optimum(x));
  any.observe(x, control, twin.quality(x, control));
  VectorX estimate = VectorX::Constant(2, 1.0);
  MatrixX covariance = MatrixX::Zero(2, 2);
  any.offset_estimate(estimate);
  any.offset_covariance(covariance);
  EXPECT_EQ(estimate, VectorX::Zero(2));
  EXPECT_TRUE(covariance.array().isNaN().all());
  EXPECT_TRUE(std::isnan(any.offset_covariance_trace()));
  EXPECT_EQ(any.step_report(), nlohmann::json::object()) << "it reports nothing more";
}

// The active controller's step report is its last_step(), field for field, after every step.
TEST(AnyController, ReportsTheActiveControllersLastStep) {
  const AnalyticTwin twin = make_twin(3);
  const RandomStream stream(12);
  ActiveController<AnalyticTwin, Dynamic> direct(twin, stream);
  AnyController any(ActiveController<AnalyticTwin, Dynamic>(twin, stream), 3);
  const VectorX offset = VectorX::Constant(3, 0.05);
  VectorX control(3);
  for (const AssemblyId& x : any_controller_assemblies()) {
    any.propose(x, control);
    const VectorX expected = direct.propose(x);
    const double z = twin.quality(x, VectorX(control - offset));
    any.observe(x, control, z);
    direct.observe(x, expected, z);
    EXPECT_EQ(any.step_report(), active_step_report_to_json(direct.last_step()));
  }
  EXPECT_TRUE(any.step_report()["quadratic"].get<bool>());
  EXPECT_EQ(any.step_report()["history"], 6);
}

}  // namespace
}  // namespace twincal
