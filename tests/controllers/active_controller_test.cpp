#include "twincal/controllers/active_controller.hpp"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "controller_fixture.hpp"
#include "twincal/controllers/information_probe.hpp"
#include "twincal/filters/simplex_sigma_points.hpp"
#include "twincal/models/rugged_twin.hpp"

namespace twincal {
namespace {

using testing::CountingTwin;

static_assert(EstimatingController<ActiveController<CountingTwin, 3>>);
static_assert(EstimatingController<ActiveController<CountingTwin, Dynamic>>);
static_assert(ProbeDesign<InformationProbe<3>, 3>);
static_assert(ProbeDesign<NoProbe<Dynamic>, Dynamic>);

template <typename C>
class ActiveControllerTest : public ::testing::Test {};
using ActiveControllers =
    ::testing::Types<ActiveController<CountingTwin, 3>, ActiveController<CountingTwin, Dynamic>,
                     ActiveCalibrationController<CountingTwin, Dynamic, InformationProbe<Dynamic>,
                                                 SimplexSigmaPoints>>;
TYPED_TEST_SUITE(ActiveControllerTest, ActiveControllers);

// Runs `steps` assemblies of the plant Q(x, u − δu*) with a constant offset; returns the final
// estimation error and checks every control against the twin's bounds widened by the largest
// correction (ActiveOptions::max_offset_fraction of the box width).
template <typename C>
double track(C& controller, const testing::AnalyticTwin& twin, const VectorX& offset, int steps) {
  const std::vector<AssemblyId> assemblies = twin.assemblies();
  for (int t = 0; t < steps; ++t) {
    const AssemblyId& x = assemblies[static_cast<std::size_t>(t) % assemblies.size()];
    const typename C::ControlVector u = controller.propose(x);
    const VectorX margin =
        ActiveOptions{}.max_offset_fraction * (twin.upper_bounds() - twin.lower_bounds());
    EXPECT_TRUE((u.array() >= (twin.lower_bounds() - margin).array()).all());
    EXPECT_TRUE((u.array() <= (twin.upper_bounds() + margin).array()).all());
    controller.observe(x, u, twin.quality(x, VectorX(u - offset)));
  }
  return (VectorX(controller.offset_estimate()) - offset).norm();
}

TYPED_TEST(ActiveControllerTest, TracksAConstantOffsetOfEveryLocatorWithinItsBudget) {
  const testing::AnalyticTwin twin = testing::make_twin(3);
  const CountingTwin counting(twin);
  TypeParam controller(counting, RandomStream(1));
  const VectorX offset = Eigen::Vector3d(0.15, -0.1, 0.05);
  EXPECT_LT(track(controller, twin, offset, 80), 0.03);
  // Q-evaluations per assembly ≤ 4 (d + 1)² (the budget) on average.
  EXPECT_LE(counting.stats().evaluations, 80U * 4U * 16U);
}

TYPED_TEST(ActiveControllerTest, RecoversFromAnOverconfidentMirrorImageStart) {
  const testing::AnalyticTwin twin = testing::make_twin(3);
  const CountingTwin counting(twin);
  TypeParam controller(counting, RandomStream(2));
  const VectorX offset = Eigen::Vector3d(0.2, -0.15, 0.1);
  // δû = −δu*: at u = u0 + δû the quality is that of the true offset's mirror image.
  controller.restart(-offset,
                     SquareMatrix<TypeParam::dimension_at_compile_time>::Identity(3, 3) * 1e-5);
  EXPECT_LT(track(controller, twin, offset, 120), 0.05);
}

TYPED_TEST(ActiveControllerTest, ClipsControlsToTheTwinBoundsWhenTheEstimateIsLost) {
  const testing::AnalyticTwin twin = testing::make_twin(3);
  const CountingTwin counting(twin);
  TypeParam controller(counting, RandomStream(3));
  controller.restart(Eigen::Vector3d::Constant(5.0),
                     SquareMatrix<TypeParam::dimension_at_compile_time>::Identity(3, 3) * 1e-3);
  const AssemblyId x{2, 3};
  const VectorX u = controller.propose(x);
  // δû = 5 is applied as the largest correction, ½ of the box width 2: u − 1 is in the box.
  const VectorX twin_frame = u - VectorX::Ones(3);
  EXPECT_TRUE((twin_frame.array() >= twin.lower_bounds().array()).all()) << u.transpose();
  EXPECT_TRUE((twin_frame.array() <= twin.upper_bounds().array()).all()) << u.transpose();
  TypeParam uncorrected(counting, RandomStream(3), ActiveOptions{.max_offset_fraction = 0.0});
  uncorrected.restart(Eigen::Vector3d::Constant(5.0),
                      SquareMatrix<TypeParam::dimension_at_compile_time>::Identity(3, 3) * 1e-3);
  // Without corrections the control is the twin-frame one (up to the rounding of u − 1).
  EXPECT_LT((VectorX(uncorrected.propose(x)) - twin_frame).cwiseAbs().maxCoeff(), 1e-12);
}

TYPED_TEST(ActiveControllerTest, RefusesANonFiniteQualityAndKeepsItsState) {
  const testing::AnalyticTwin twin = testing::make_twin(3);
  const CountingTwin counting(twin);
  TypeParam controller(counting, RandomStream(4));
  const AssemblyId x{1, 1};
  const typename TypeParam::ControlVector u = controller.propose(x);
  const VectorX before = controller.offset_estimate();
  const MatrixX covariance = controller.offset_covariance();
  EXPECT_THROW(controller.observe(x, u, std::numeric_limits<double>::quiet_NaN()), NonFiniteError);
  EXPECT_EQ(VectorX(controller.offset_estimate()), before);
  EXPECT_EQ(controller.offset_covariance(), covariance);
}

TEST(ActiveController, FallsBackToSigmaPointsForATwinThatIsNotQuadratic) {
  const RuggedTwin twin(RuggedTwinOptions{}, RandomStream(5));
  ActiveController<RuggedTwin, Dynamic> controller(twin, RandomStream(6));
  const VectorX offset = Eigen::Vector3d(0.05, -0.04, 0.03);
  const std::vector<AssemblyId> assemblies = twin.assemblies();
  for (int t = 0; t < 40; ++t) {
    const AssemblyId& x = assemblies[static_cast<std::size_t>(t)];
    const VectorX u = controller.propose(x);
    EXPECT_FALSE(controller.last_step().quadratic) << "assembly " << t;
    controller.observe(x, u, twin.quality(x, VectorX(u - offset)));
    ASSERT_TRUE(controller.offset_estimate().allFinite());
  }
  // Sigma points keep the estimate bounded near the offset's scale.
  EXPECT_LT((controller.offset_estimate() - offset).norm(), 0.3);
}

TEST(ActiveController, OptionsNameTheRuleTheyBreak) {
  EXPECT_EQ(ActiveOptions{.measurement_variance = -1.0}.validate(),
            "measurement_variance is -1; it must be finite and > 0");
  EXPECT_EQ(ActiveOptions{.max_offset_fraction = -0.1}.validate(),
            "max_offset_fraction is -0.1; it must lie in [0, 1]");
  EXPECT_EQ(ActiveOptions{.surrogate = {.tolerance = 0.0}}.validate(),
            "surrogate.tolerance is 0; it must be finite and > 0");
  const testing::AnalyticTwin twin = testing::make_twin(2);
  EXPECT_THROW((ActiveController<testing::AnalyticTwin, Dynamic>(
                   twin, RandomStream(1), ActiveOptions{.max_probe_fraction = 2.0})),
               InvalidArgumentError);
}

}  // namespace
}  // namespace twincal
