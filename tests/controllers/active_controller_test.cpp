#include "twincal/controllers/presets.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "controller_fixture.hpp"
#include "twincal/controllers/active/information_probe.hpp"
#include "twincal/controllers/searched_optimum_twin.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/filters/simplex_sigma_points.hpp"
#include "twincal/models/bouncing_drift.hpp"
#include "twincal/models/contact_nonlinearity.hpp"
#include "twincal/models/key_point_twin.hpp"
#include "twincal/models/kink_nonlinearity.hpp"
#include "twincal/models/no_nonlinearity.hpp"
#include "twincal/models/rugged_twin.hpp"
#include "twincal/models/stiffening_nonlinearity.hpp"

namespace twincal {
namespace {

using test_support::CountingTwin;

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

// A wanted correction is applied exactly when no reason to hold it back is set.
void expect_holds_explain_the_control(const ActiveStepReport& step, int t) {
  const bool held = step.held_by_innovations || step.held_by_surprises || step.held_beyond_reach ||
                    step.held_by_audit;
  EXPECT_EQ(step.corrected, step.correction_wanted && !held) << "proposal " << t;
  EXPECT_TRUE(!step.held_by_audit || step.audited) << "proposal " << t;
}

// Runs `steps` assemblies of the plant Q(x, u − δu*) with a constant offset; returns the final
// estimation error and checks every control against the twin's bounds widened by the largest
// correction (ActiveOptions::max_offset_fraction of the box width).
template <typename C>
double track(C& controller, const test_support::AnalyticTwin& twin, const VectorX& offset,
             int steps) {
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
  const test_support::AnalyticTwin twin = test_support::make_twin(3);
  const CountingTwin counting(twin);
  TypeParam controller(counting, RandomStream(1));
  const VectorX offset = Eigen::Vector3d(0.15, -0.1, 0.05);
  EXPECT_LT(track(controller, twin, offset, 80), 0.03);
  // Q-evaluations per assembly ≤ 4 (d + 1)² (the budget) on average.
  EXPECT_LE(counting.stats().evaluations, 80U * 4U * 16U);
}

TYPED_TEST(ActiveControllerTest, RecoversFromAnOverconfidentMirrorImageStart) {
  const test_support::AnalyticTwin twin = test_support::make_twin(3);
  const CountingTwin counting(twin);
  TypeParam controller(counting, RandomStream(2));
  const VectorX offset = Eigen::Vector3d(0.2, -0.15, 0.1);
  // δû = −δu*: at u = u0 + δû the quality is that of the true offset's mirror image.
  controller.restart(-offset,
                     SquareMatrix<TypeParam::dimension_at_compile_time>::Identity(3, 3) * 1e-5);
  EXPECT_LT(track(controller, twin, offset, 120), 0.05);
}

// With clamp_beyond_reach, a lost estimate is applied clamped to the correction's reach (by
// default it is not applied at all: LeavesAnEstimateBeyondTheCorrectionsReachUnapplied).
TYPED_TEST(ActiveControllerTest, ClipsControlsToTheTwinBoundsWhenTheEstimateIsLost) {
  const test_support::AnalyticTwin twin = test_support::make_twin(3);
  const CountingTwin counting(twin);
  TypeParam controller(counting, RandomStream(3), ActiveOptions{.clamp_beyond_reach = true});
  controller.restart(Eigen::Vector3d::Constant(5.0),
                     SquareMatrix<TypeParam::dimension_at_compile_time>::Identity(3, 3) * 1e-3);
  const AssemblyId x{2, 3};
  const VectorX u = controller.propose(x);
  // δû = 5 is applied as the largest correction, ½ of the box width 2: u − 1 is in the box.
  const VectorX twin_frame = u - VectorX::Ones(3);
  EXPECT_TRUE((twin_frame.array() >= twin.lower_bounds().array()).all()) << u.transpose();
  EXPECT_TRUE((twin_frame.array() <= twin.upper_bounds().array()).all()) << u.transpose();
  TypeParam uncorrected(counting, RandomStream(3),
                        ActiveOptions{.max_offset_fraction = 0.0, .clamp_beyond_reach = true});
  uncorrected.restart(Eigen::Vector3d::Constant(5.0),
                      SquareMatrix<TypeParam::dimension_at_compile_time>::Identity(3, 3) * 1e-3);
  // Without corrections the control is the twin-frame one (up to the rounding of u − 1).
  EXPECT_LT((VectorX(uncorrected.propose(x)) - twin_frame).cwiseAbs().maxCoeff(), 1e-12);
}

// The correction the controller's last proposal applied: u less clip(u0, box) (and its probe,
// which these tests keep negligible).
template <typename Controller>
VectorX applied_correction(const Controller& controller, const VectorX& u, const VectorX& lower,
                           const VectorX& upper) {
  return u - controller.last_proposal().individual_control.cwiseMax(lower).cwiseMin(upper);
}

// With correction_step_fraction, the applied correction moves at most that fraction of the box
// width per locator from one proposal to the next, here from 0 to an estimate given by restart()
// (applied at once without the bound), and then reaches it. Probes are kept negligible so that
// the correction is the control less clip(u0, box).
TYPED_TEST(ActiveControllerTest, MovesTheCorrectionAtMostItsStepPerAssembly) {
  const test_support::AnalyticTwin twin = test_support::make_twin(3);
  const CountingTwin counting(twin);
  const VectorX offset = Eigen::Vector3d(0.3, -0.25, 0.2);
  const VectorX lower = twin.lower_bounds();
  const VectorX upper = twin.upper_bounds();
  const auto correction = [&](const auto& controller, const VectorX& u) {
    return applied_correction(controller, u, lower, upper);
  };
  const auto start = [&](TypeParam& controller) {
    controller.restart(offset,
                       SquareMatrix<TypeParam::dimension_at_compile_time>::Identity(3, 3) * 1e-6);
  };
  const std::vector<AssemblyId> assemblies = twin.assemblies();
  TypeParam unbounded(counting, RandomStream(12), ActiveOptions{.max_probe_fraction = 1e-9});
  start(unbounded);
  const VectorX first = unbounded.propose(assemblies[0]);
  EXPECT_LT((correction(unbounded, first) - offset).cwiseAbs().maxCoeff(), 1e-6);

  const ActiveOptions options{.max_probe_fraction = 1e-9, .correction_step_fraction = 0.01};
  TypeParam bounded(counting, RandomStream(12), options);
  start(bounded);
  const VectorX step = options.correction_step_fraction * (upper - lower);  // 0.02 per locator
  VectorX last = VectorX::Zero(3);
  for (int t = 0; t < 30; ++t) {
    const AssemblyId& x = assemblies[static_cast<std::size_t>(t) % assemblies.size()];
    const VectorX u = bounded.propose(x);
    const VectorX applied = correction(bounded, u);
    EXPECT_TRUE(((applied - last).cwiseAbs().array() <= step.array() + 1e-8).all())
        << "assembly " << t << ": " << applied.transpose() << " after " << last.transpose();
    last = applied;
    bounded.observe(x, u, twin.quality(x, VectorX(u - offset)));
  }
  // 0.3 / 0.02 = 15 assemblies to reach the estimate, which stayed at the offset.
  EXPECT_LT((last - VectorX(bounded.offset_estimate())).cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_LT((last - offset).cwiseAbs().maxCoeff(), 0.02);
}

// An estimate beyond the correction's reach (max_offset_fraction of the box width on some
// locator) is not applied, the control staying at u0 + p, unless clamp_beyond_reach, which applies
// it clamped to the reach; an estimate within the reach is applied either way.
TYPED_TEST(ActiveControllerTest, LeavesAnEstimateBeyondTheCorrectionsReachUnapplied) {
  const test_support::AnalyticTwin twin = test_support::make_twin(3);
  const CountingTwin counting(twin);
  const VectorX lower = twin.lower_bounds();
  const VectorX upper = twin.upper_bounds();
  const ActiveOptions defaults{};
  const VectorX reach = defaults.max_offset_fraction * (upper - lower);
  const AssemblyId x = twin.assemblies().front();
  // The correction of the first proposal after restart(estimate), and whether it was applied.
  const auto first_correction = [&](const VectorX& estimate, bool clamp) {
    TypeParam controller(counting, RandomStream(12),
                         ActiveOptions{.max_probe_fraction = 1e-9, .clamp_beyond_reach = clamp});
    controller.restart(estimate,
                       SquareMatrix<TypeParam::dimension_at_compile_time>::Identity(3, 3) * 1e-6);
    const VectorX u = controller.propose(x);
    const ActiveStepReport& step = controller.last_step();
    expect_holds_explain_the_control(step, 0);
    EXPECT_EQ(step.held_beyond_reach, !clamp && (estimate.array().abs() > reach.array()).any());
    return std::pair{applied_correction(controller, u, lower, upper), step.corrected};
  };
  const VectorX within = reach.cwiseProduct(Eigen::Vector3d(0.9, -0.5, 0.2));
  VectorX beyond = within;
  beyond(0) = 1.1 * reach(0);
  VectorX clamped = beyond;
  clamped(0) = reach(0);
  for (const bool clamp : {false, true}) {
    const auto [correction, corrected] = first_correction(within, clamp);
    EXPECT_TRUE(corrected) << "clamp_beyond_reach " << clamp;
    EXPECT_LT((correction - within).cwiseAbs().maxCoeff(), 1e-6) << correction.transpose();
  }
  const auto [held, held_corrected] = first_correction(beyond, false);
  EXPECT_FALSE(held_corrected);
  EXPECT_LT(held.cwiseAbs().maxCoeff(), 1e-6) << held.transpose();
  const auto [applied, applied_corrected] = first_correction(beyond, true);
  EXPECT_TRUE(applied_corrected);
  EXPECT_LT((applied - clamped).cwiseAbs().maxCoeff(), 1e-6) << applied.transpose();
}

// With surprise_step_fraction, a correction right after a surprise — a z beyond the innovation
// gate that the refit does not explain either (here one answer of the plant from an offset
// moved by 0.6 on every locator, among answers from the offset the controller was restarted at)
// — moves at most that fraction of the box width per locator from the last one applied. Before
// the surprise the controller corrects as one without the bound (the plant is the twin: nothing
// surprises); after it, the unbounded one moves further than the bound allows, and an estimate
// given by restart() is applied at once.
TYPED_TEST(ActiveControllerTest, BoundsTheCorrectionRightAfterASurprise) {
  const test_support::AnalyticTwin twin = test_support::make_twin(3);
  const CountingTwin counting(twin);
  const VectorX offset = Eigen::Vector3d(0.3, -0.25, 0.2);
  const VectorX moved = Eigen::Vector3d(0.2, -0.15, 0.1);  // an estimate given after it
  const std::vector<AssemblyId> assemblies = twin.assemblies();
  const auto run = [&](double fraction, bool restart_after_surprise = false) {
    TypeParam controller(
        counting, RandomStream(12),
        ActiveOptions{.max_probe_fraction = 1e-9, .surprise_step_fraction = fraction});
    const auto start = [&](const VectorX& estimate) {
      controller.restart(estimate,
                         SquareMatrix<TypeParam::dimension_at_compile_time>::Identity(3, 3) * 1e-6);
    };
    start(offset);
    std::vector<VectorX> corrections;
    for (int t = 0; t < 14; ++t) {
      const AssemblyId& x = assemblies[static_cast<std::size_t>(t) % assemblies.size()];
      const VectorX u = controller.propose(x);
      corrections.push_back(
          applied_correction(controller, u, twin.lower_bounds(), twin.upper_bounds()));
      const VectorX plant_offset = t == 12 ? VectorX(offset.array() + 0.6) : offset;
      controller.observe(x, u, twin.quality(x, VectorX(u - plant_offset)));
      const ActiveStepReport& step = controller.last_step();
      const bool surprise = step.normalized_innovation > 25.0 && step.normalized_residual > 1.0;
      if (t <= 12) {
        EXPECT_EQ(surprise, t == 12)
            << "assembly " << t << ": nu^2/S " << step.normalized_innovation << ", residual "
            << step.normalized_residual;
      }
      if (t == 12 && restart_after_surprise) start(moved);
    }
    return corrections;
  };
  const double fraction = 0.001;
  const VectorX step = fraction * (twin.upper_bounds() - twin.lower_bounds());  // 0.002
  const std::vector<VectorX> unbounded = run(0.0);
  const std::vector<VectorX> bounded = run(fraction);
  for (std::size_t t = 0; t <= 12; ++t) EXPECT_EQ(bounded[t], unbounded[t]) << "assembly " << t;
  // Up to the probes (at most 2e-9 per locator each).
  EXPECT_TRUE(((bounded[13] - bounded[12]).cwiseAbs().array() <= step.array() + 1e-8).all())
      << bounded[13].transpose() << " after " << bounded[12].transpose();
  EXPECT_GT((unbounded[13] - unbounded[12]).cwiseAbs().maxCoeff(), 5.0 * step.maxCoeff());
  // An estimate given by restart() after the surprise is applied at once.
  const std::vector<VectorX> restarted = run(fraction, true);
  EXPECT_LT((restarted[13] - moved).cwiseAbs().maxCoeff(), 1e-8) << restarted[13].transpose();
}

// The episode of the surprise tests: a controller restarted at the plant's offset (0.3, −0.25,
// 0.2) with P = 1e-6 I runs `steps` assemblies of the analytic twin with that offset, but for
// assembly `jump`, whose answer comes from the offset moved by 0.6 on every locator.
struct JumpRun {
  std::vector<VectorX> controls;        // by proposal
  std::vector<bool> corrected;          // by proposal
  std::vector<bool> held_by_surprises;  // by proposal
  std::vector<bool> audited;            // by proposal
  std::vector<bool> gated;              // by observation: ν²/S beyond the gate (5²)
  std::vector<bool> surprised;          // by observation: gated, and unexplained by the refit
  nlohmann::json snapshot;              // the state before proposal `snapshot_at`
};

const VectorX& jump_offset() {
  static const VectorX offset = Eigen::Vector3d(0.3, -0.25, 0.2);
  return offset;
}

// Assembly t of the surprise tests' episode (the twin's assemblies in turn).
AssemblyId jump_assembly(const test_support::AnalyticTwin& twin, int t) {
  const std::vector<AssemblyId> assemblies = twin.assemblies();
  return assemblies[static_cast<std::size_t>(t) % assemblies.size()];
}

// The restart the surprise tests' episode starts from: δû = the plant's offset, P = 1e-6 I.
template <typename C>
void restart_at_jump_offset(C& controller) {
  controller.restart(jump_offset(),
                     SquareMatrix<C::dimension_at_compile_time>::Identity(3, 3) * 1e-6);
}

template <typename C>
JumpRun run_with_one_jump(const CountingTwin& counting, const ActiveOptions& options,
                          std::optional<int> jump, int steps, int snapshot_at) {
  const test_support::AnalyticTwin& twin = counting.twin();
  C controller(counting, RandomStream(12), options);
  restart_at_jump_offset(controller);
  JumpRun result;
  for (int t = 0; t < steps; ++t) {
    if (t == snapshot_at) result.snapshot = controller.save();
    const AssemblyId x = jump_assembly(twin, t);
    const VectorX u = controller.propose(x);
    result.controls.push_back(u);
    result.corrected.push_back(controller.last_step().corrected);
    result.held_by_surprises.push_back(controller.last_step().held_by_surprises);
    result.audited.push_back(controller.last_step().audited);
    expect_holds_explain_the_control(controller.last_step(), t);
    const VectorX plant_offset = jump == t ? VectorX(jump_offset().array() + 0.6) : jump_offset();
    controller.observe(x, u, twin.quality(x, VectorX(u - plant_offset)));
    const ActiveStepReport& step = controller.last_step();
    result.gated.push_back(step.normalized_innovation > 25.0);
    result.surprised.push_back(result.gated.back() && step.normalized_residual > 1.0);
  }
  return result;
}

// With hold_after_surprises (2 by default), the estimate is not applied while that many of the
// last change_window + 3 = 5 assemblies were surprises the refit does not explain. Here one
// answer of the plant comes from an offset moved by 0.6 on every locator (assembly 10), among
// answers from the offset the controller was restarted at: it surprises, and so does the next
// assembly, whose estimate it pulled away. Proposal 12 then holds the estimate back where the
// controller without the rule applies it, and every proposal after two surprises within five
// does; once they leave the ring the estimate is applied again. A snapshot taken while it is
// held back holds it back once restored, and an estimate given by restart() is applied at once.
TYPED_TEST(ActiveControllerTest, HoldsTheCorrectionBackAfterUnexplainedSurprises) {
  const test_support::AnalyticTwin twin = test_support::make_twin(3);
  const CountingTwin counting(twin);
  const auto options = [](Index hold) {
    return ActiveOptions{.max_probe_fraction = 1e-9, .hold_after_surprises = hold};
  };
  const auto run = [&](Index hold) {
    return run_with_one_jump<TypeParam>(counting, options(hold), 10, 19, 12);
  };
  const JumpRun by_default = run(ActiveOptions{}.hold_after_surprises);
  const JumpRun never = run(0);
  for (std::size_t t = 0; t < 12; ++t) {
    EXPECT_TRUE(by_default.corrected[t] && never.corrected[t]) << "proposal " << t;
    EXPECT_FALSE(by_default.held_by_surprises[t]) << "proposal " << t;
    EXPECT_EQ(by_default.surprised[t], t >= 10) << "assembly " << t;
  }
  EXPECT_FALSE(by_default.corrected[12]);
  EXPECT_TRUE(never.corrected[12]);
  for (std::size_t t = 12; t < 19; ++t) {
    const auto surprises =
        std::count(by_default.surprised.begin() + static_cast<std::ptrdiff_t>(t) - 5,
                   by_default.surprised.begin() + static_cast<std::ptrdiff_t>(t), true);
    if (surprises >= 2) {
      EXPECT_FALSE(by_default.corrected[t]) << "proposal " << t;
      EXPECT_TRUE(by_default.held_by_surprises[t]) << "proposal " << t;
    }
  }
  EXPECT_TRUE(by_default.corrected[18]);
  EXPECT_FALSE(by_default.held_by_surprises[18]);
  EXPECT_TRUE(std::none_of(never.held_by_surprises.begin(), never.held_by_surprises.end(),
                           [](bool held) { return held; }));

  const AssemblyId x = jump_assembly(twin, 12);
  TypeParam restored(counting, RandomStream(12), options(2));
  restored.restore(by_default.snapshot);
  (void)restored.propose(x);
  EXPECT_FALSE(restored.last_step().corrected);
  restored.restore(by_default.snapshot);
  restart_at_jump_offset(restored);
  (void)restored.propose(x);
  EXPECT_TRUE(restored.last_step().corrected);
}

// With trial_innovations, a z beyond the innovation gate among the episode's first innovations
// is a surprise whether the refit explains it or not, and it alone holds the estimate back while
// it is among the last change_window + 3 = 5 assemblies. Here hold_after_surprises is 0, so the
// trial is the only rule that holds for surprises: one answer of the plant from an offset moved
// by 0.6 on every locator (assembly 1, within the trial of 5) holds the next proposals back
// until that surprise and any the trial saw after it have left the ring, where the controller
// without a trial applies them; the same jump at assembly 10, after the trial, holds nothing.
// Where the twin predicts the plant the trial changes no control. A snapshot taken during the
// hold holds once restored (one whose trial surprise lies beyond the innovations counted is
// refused), and restart() ends the hold.
TYPED_TEST(ActiveControllerTest, HoldsTheCorrectionBackAfterASurpriseOfTheTrial) {
  const test_support::AnalyticTwin twin = test_support::make_twin(3);
  const CountingTwin counting(twin);
  const auto options = [](Index trial) {
    return ActiveOptions{
        .max_probe_fraction = 1e-9, .hold_after_surprises = 0, .trial_innovations = trial};
  };
  const auto run = [&](Index trial, std::optional<int> jump) {
    return run_with_one_jump<TypeParam>(counting, options(trial), jump, 16, 2);
  };

  const JumpRun predicted = run(5, std::nullopt);
  EXPECT_EQ(predicted.controls, run(0, std::nullopt).controls);
  EXPECT_TRUE(std::none_of(predicted.gated.begin(), predicted.gated.end(),
                           [](bool gated) { return gated; }));

  const JumpRun trial = run(5, 1);
  const JumpRun no_trial = run(0, 1);
  ASSERT_TRUE(trial.gated[1]);
  // The last surprise of the trial (observations 0 … 4) and the proposals it holds.
  int last = 1;
  for (int t = 2; t < 5; ++t) last = trial.gated[static_cast<std::size_t>(t)] ? t : last;
  const auto never_held = [](const JumpRun& r) {
    return std::none_of(r.held_by_surprises.begin(), r.held_by_surprises.end(),
                        [](bool held) { return held; });
  };
  for (std::size_t t = 0; t < 16; ++t) {
    const bool within = t >= 2 && static_cast<int>(t) <= last + 5;
    EXPECT_EQ(trial.held_by_surprises[t], within) << "proposal " << t;
    if (within) EXPECT_FALSE(trial.corrected[t]) << "proposal " << t;
  }
  EXPECT_TRUE(trial.corrected[static_cast<std::size_t>(last) + 6]);
  // Without the trial the controller applies the estimate at once, unless the innovations rule
  // holds it (four of the last five beyond the gate).
  EXPECT_TRUE(no_trial.corrected[2]);
  EXPECT_TRUE(never_held(no_trial));

  const JumpRun after_trial = run(5, 10);
  ASSERT_TRUE(after_trial.gated[10]);
  EXPECT_TRUE(never_held(after_trial));

  const AssemblyId x = jump_assembly(twin, 2);
  TypeParam restored(counting, RandomStream(12), options(5));
  // A trial's surprise later than the innovations counted is refused, the state unchanged.
  nlohmann::json bad = trial.snapshot;
  bad["trial_surprise"] = 3;  // two innovations were counted
  const std::string before = restored.save().dump();
  EXPECT_THAT([&] { restored.restore(bad); },
              ::testing::ThrowsMessage<InvalidArgumentError>(
                  ::testing::HasSubstr("trial_surprise: is 3; rule: must lie in [0, 2]")));
  EXPECT_EQ(restored.save().dump(), before);
  restored.restore(trial.snapshot);
  (void)restored.propose(x);
  EXPECT_FALSE(restored.last_step().corrected);
  EXPECT_TRUE(restored.last_step().held_by_surprises);
  restored.restore(trial.snapshot);
  restart_at_jump_offset(restored);
  (void)restored.propose(x);
  EXPECT_TRUE(restored.last_step().corrected);
}

// With audit_after_failed_trial, a twin whose trial saw a surprise is in doubt from then on:
// its corrections are audited on the plant's answers, although its model passes its check and
// one jump of the plant leaves the prediction scale far below audit_misfit. Without the option,
// or without a failed trial (no jump, or the jump after the trial), nothing is audited. A
// snapshot keeps the doubt, and so does restart().
TYPED_TEST(ActiveControllerTest, AuditsATwinThatFailedItsTrial) {
  const test_support::AnalyticTwin twin = test_support::make_twin(3);
  const CountingTwin counting(twin);
  // No position floor at the restart the jump sets off: with it (the default) the restart's
  // wider prior lets the next fits move, and their prediction scale alone crosses audit_misfit
  // (12 of 30 assemblies audited without the option), so the scenario would no longer isolate
  // the failed trial as the audit's cause.
  const auto options = [](bool audit) {
    return ActiveOptions{.trajectory = {.change_position_floor_fraction = 0.0},
                         .max_probe_fraction = 1e-9,
                         .hold_after_surprises = 0,
                         .trial_innovations = 5,
                         .audit_after_failed_trial = audit};
  };
  const auto run = [&](bool audit, std::optional<int> jump) {
    return run_with_one_jump<TypeParam>(counting, options(audit), jump, 30, 20);
  };
  const auto audits = [](const JumpRun& r) {
    return std::count(r.audited.begin(), r.audited.end(), true);
  };
  const JumpRun failed = run(true, 1);
  EXPECT_FALSE(failed.audited[0] || failed.audited[1]);
  EXPECT_GT(audits(failed), 10);
  EXPECT_EQ(audits(run(false, 1)), 0);
  EXPECT_EQ(audits(run(true, std::nullopt)), 0);
  EXPECT_EQ(audits(run(true, 10)), 0);

  const AssemblyId x = jump_assembly(twin, 20);
  TypeParam restored(counting, RandomStream(12), options(true));
  restored.restore(failed.snapshot);
  (void)restored.propose(x);
  EXPECT_EQ(restored.last_step().audited, failed.audited[20]);
  EXPECT_TRUE(restored.last_step().audited);
  restored.restore(failed.snapshot);
  restart_at_jump_offset(restored);
  (void)restored.propose(x);
  EXPECT_TRUE(restored.last_step().audited);
}

TYPED_TEST(ActiveControllerTest, RefusesANonFiniteQualityAndKeepsItsState) {
  const test_support::AnalyticTwin twin = test_support::make_twin(3);
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

// Assembly t of the plant Q(x, u − δu*_t) under a slow drift; returns u_t.
template <typename C, typename T>
VectorX drifting_step(C& controller, const T& twin, const std::vector<AssemblyId>& assemblies,
                      int t) {
  const AssemblyId& x = assemblies[static_cast<std::size_t>(t) % assemblies.size()];
  const VectorX u = controller.propose(x);
  const double s = static_cast<double>(t);
  const VectorX offset = Eigen::Vector3d(0.1 * std::sin(0.05 * s), -0.08 + 0.002 * s, 0.05);
  controller.observe(x, typename C::ControlVector(u), twin.quality(x, VectorX(u - offset)));
  return u;
}

TEST(ActiveController, FallsBackToSigmaPointsForATwinThatIsNotQuadraticWhenAskedTo) {
  const RuggedTwin twin(RuggedTwinOptions{}, RandomStream(5));
  ActiveController<RuggedTwin, Dynamic> controller(twin, RandomStream(6),
                                                   ActiveOptions{.weigh_model_error = false});
  const VectorX offset = Eigen::Vector3d(0.05, -0.04, 0.03);
  const std::vector<AssemblyId> assemblies = twin.assemblies();
  for (int t = 0; t < 40; ++t) {
    const AssemblyId& x = assemblies[static_cast<std::size_t>(t)];
    const VectorX u = controller.propose(x);
    EXPECT_FALSE(controller.last_step().quadratic) << "assembly " << t;
    controller.observe(x, u, twin.quality(x, VectorX(u - offset)));
    ASSERT_TRUE(controller.offset_estimate().allFinite());
    // No estimator ran: its readings are NaN, not a number that was never measured.
    EXPECT_TRUE(std::isnan(controller.last_step().change_ratio));
    EXPECT_TRUE(std::isnan(controller.last_step().misfit_scale));
    EXPECT_TRUE(std::isnan(controller.last_step().prediction_scale));
  }
  // Sigma points keep the estimate bounded near the offset's scale.
  EXPECT_LT((controller.offset_estimate() - offset).norm(), 0.3);
}

// A twin that fails everywhere (TwinError, behind an Evaluator): the model cannot be fitted, so
// the proposal falls back to the sigma-point mode, and its update cannot be evaluated either, so
// the measurement is dropped — the estimate and P stay as predicted — and the controller goes on.
TEST(ActiveController, FallsBackAndDropsTheMeasurementWhereItsTwinFails) {
  const test_support::AnalyticTwin inner = test_support::make_twin(3);
  const test_support::FailingOnLargeBatches failing(inner, 0);
  using Checked = Evaluator<test_support::FailingOnLargeBatches>;
  const Checked twin(failing);
  ActiveController<Checked, Dynamic> controller(twin, RandomStream(6));
  const std::vector<AssemblyId> assemblies = inner.assemblies();
  for (int t = 0; t < 3; ++t) {
    const AssemblyId& x = assemblies[static_cast<std::size_t>(t)];
    const VectorX u = controller.propose(x);
    // A twin's failure says nothing about its model: the fit is tried again at every assembly.
    EXPECT_TRUE(controller.last_proposal().fell_back()) << "assembly " << t;
    EXPECT_FALSE(controller.last_step().quadratic) << "assembly " << t;
    const VectorX predicted = controller.offset_estimate();
    const MatrixX predicted_covariance = controller.offset_covariance();
    controller.observe(x, u, 0.5);
    EXPECT_TRUE(controller.last_proposal().dropped()) << "assembly " << t;
    EXPECT_THAT(controller.last_proposal().dropped_measurement,
                ::testing::HasSubstr("FEM solver crashed"));
    EXPECT_EQ(controller.offset_estimate(), predicted);
    EXPECT_EQ(controller.offset_covariance(), predicted_covariance);
  }
}

// The default for a twin whose Q² is not a quadratic: the model is still used, each assembly
// weighted by its model's error (τ² > 0), and the estimate is the estimator's.
TEST(ActiveController, WeighsTheModelErrorOfATwinThatIsNotQuadratic) {
  const RuggedTwin twin(RuggedTwinOptions{}, RandomStream(5));
  ActiveController<RuggedTwin, Dynamic> controller(twin, RandomStream(6));
  const VectorX offset = Eigen::Vector3d(0.05, -0.04, 0.03);
  const std::vector<AssemblyId> assemblies = twin.assemblies();
  for (int t = 0; t < 40; ++t) {
    const AssemblyId& x = assemblies[static_cast<std::size_t>(t)];
    const VectorX u = controller.propose(x);
    EXPECT_TRUE(controller.last_step().quadratic) << "assembly " << t;
    EXPECT_GT(controller.last_step().model_error, controller.options().surrogate.tolerance);
    EXPECT_GT(controller.last_step().model_variance, 0.0);
    EXPECT_TRUE(controller.last_step().hessian_refitted) << "a failed check refits H";
    controller.observe(x, u, twin.quality(x, VectorX(u - offset)));
    ASSERT_TRUE(controller.offset_estimate().allFinite());
    // The estimator's readings, as it defines them: scales of at least 1, and the gate's
    // reading once the history is long enough to consult it (above 1 exactly at a change).
    const ActiveStepReport& step = controller.last_step();
    EXPECT_GE(step.misfit_scale, 1.0) << "assembly " << t;
    EXPECT_GE(step.prediction_scale, 1.0) << "assembly " << t;
    if (step.velocity_change) {
      EXPECT_GT(step.change_ratio, 1.0) << "assembly " << t;
    } else if (step.history >= controller.options().trajectory.change_window + 3) {
      EXPECT_LE(step.change_ratio, 1.0) << "assembly " << t;
      EXPECT_GE(step.change_ratio, 0.0) << "assembly " << t;
    }
  }
  EXPECT_LT((controller.offset_estimate() - offset).norm(), 0.3);
}

// A twin whose local model fails its check (RuggedTwin) behind a plant with an offset it shows.
struct RuggedPlant {
  RuggedTwin twin{RuggedTwinOptions{}, RandomStream(5)};
  VectorX offset = Eigen::Vector3d(0.3, -0.25, 0.2);
  std::vector<AssemblyId> assemblies = twin.assemblies();

  [[nodiscard]] const AssemblyId& assembly(int t) const {
    return assemblies[static_cast<std::size_t>(t)];
  }
  // The plant's answer to control u for assembly t, observed by the controller.
  template <typename C>
  void answer(C& controller, int t, const VectorX& u) const {
    controller.observe(assembly(t), u, twin.quality(assembly(t), VectorX(u - offset)));
  }
};

// Probes priced by the plant's regret: on a twin whose model errs, with an offset the plant
// shows, a probe priced by regret is larger than the Probe policy's own, and the priced steps
// report the regret that priced them; the first regret_window assemblies are not priced. On a
// twin whose model passes its check the option changes nothing, control for control.
TEST(ActiveController, PricesItsProbeByThePlantsRegretWhereTheModelErrs) {
  const RuggedPlant plant;
  ActiveController<RuggedTwin, Dynamic> priced(plant.twin, RandomStream(6));
  ActiveController<RuggedTwin, Dynamic> unpriced(plant.twin, RandomStream(6),
                                                 ActiveOptions{.regret_probe = 0.0});
  const Index window = ActiveOptions{}.regret_window;
  double priced_norm = 0.0;
  double unpriced_norm = 0.0;
  int priced_steps = 0;
  for (int t = 0; t < 30; ++t) {
    const VectorX u = priced.propose(plant.assembly(t));
    const VectorX v = unpriced.propose(plant.assembly(t));
    if (t < window) EXPECT_EQ(priced.last_step().plant_regret, 0.0) << "assembly " << t;
    EXPECT_EQ(unpriced.last_step().plant_regret, 0.0);
    if (priced.last_step().plant_regret > 0.0) {
      ++priced_steps;
      priced_norm += priced.last_step().probe_norm;
      unpriced_norm += unpriced.last_step().probe_norm;
    }
    plant.answer(priced, t, u);
    plant.answer(unpriced, t, v);
  }
  EXPECT_GT(priced_steps, 15);
  EXPECT_GT(priced_norm, 3.0 * unpriced_norm);

  const test_support::AnalyticTwin quadratic = test_support::make_twin(3);
  ActiveController<test_support::AnalyticTwin, Dynamic> on(quadratic, RandomStream(6));
  ActiveController<test_support::AnalyticTwin, Dynamic> off(quadratic, RandomStream(6),
                                                            ActiveOptions{.regret_probe = 0.0});
  const std::vector<AssemblyId> parts = quadratic.assemblies();
  for (int t = 0; t < 40; ++t) {
    EXPECT_EQ(drifting_step(on, quadratic, parts, t), drifting_step(off, quadratic, parts, t))
        << "assembly " << t;
    EXPECT_EQ(on.last_step().plant_regret, 0.0);
  }
}

// A twin that answers its key points' deviations gets Gauss–Newton models: 2d + 1 evaluations
// for a fit of J, 1 with J kept, and 2 for the check; with from_deviations off, the Q² fit's
// (d + 1)(d + 2)/2 + 2 when it fits H and d + 3 otherwise. The key-point twin without a
// nonlinearity is quadratic, so both models pass their check and nothing is refitted.
TEST(ActiveController, FitsItsModelsFromTheKeyPointsDeviationsWhereTheTwinHasThem) {
  KeyPointTwinOptions options;
  options.assemblies.dimension = 3;
  const KeyPointTwin<NoNonlinearity> twin(options, RandomStream(4));
  const std::vector<AssemblyId> assemblies = twin.assemblies();
  for (const bool from_deviations : {true, false}) {
    ActiveOptions settings;
    settings.surrogate.from_deviations = from_deviations;
    ActiveController<KeyPointTwin<NoNonlinearity>, 3> controller(twin, RandomStream(5), settings);
    for (std::size_t t = 0; t < 30; ++t) {
      const AssemblyId& x = assemblies[t];
      const Vector<3> u = controller.propose(x);
      controller.observe(x, u, twin.quality(x, u));
      const bool full = t % 25 == 0;
      const std::uint64_t expected = from_deviations ? (full ? 9U : 3U) : (full ? 12U : 6U);
      EXPECT_EQ(controller.last_proposal().quality_evaluations, expected)
          << "assembly " << t << ", from_deviations " << from_deviations;
    }
  }
}

// Models refitted where the fit uses them (relinearization_reach): a reach beyond every entry's
// stencil refits nothing — the same controls as a budget of 0 — while the default reach refits
// entries on a twin whose model errs, and pays for them in twin evaluations.
TEST(ActiveController, RefitsTheModelsTheFitMovesBeyondTheirReach) {
  const RuggedPlant plant;
  ActiveController<RuggedTwin, Dynamic> refitting(plant.twin, RandomStream(6));
  ActiveController<RuggedTwin, Dynamic> out_of_reach(plant.twin, RandomStream(6),
                                                     ActiveOptions{.relinearization_reach = 1e300});
  ActiveController<RuggedTwin, Dynamic> unbudgeted(plant.twin, RandomStream(6),
                                                   ActiveOptions{.relinearization_budget = 0.0});
  std::uint64_t refitting_evaluations = 0;
  std::uint64_t out_of_reach_evaluations = 0;
  for (int t = 0; t < 30; ++t) {
    const VectorX u = refitting.propose(plant.assembly(t));
    const VectorX v = out_of_reach.propose(plant.assembly(t));
    const VectorX w = unbudgeted.propose(plant.assembly(t));
    EXPECT_TRUE(v == w) << "assembly " << t;
    plant.answer(refitting, t, u);
    plant.answer(out_of_reach, t, v);
    plant.answer(unbudgeted, t, w);
    // Refits are counted with the proposal they follow (observe adds them).
    refitting_evaluations += refitting.last_proposal().quality_evaluations;
    out_of_reach_evaluations += out_of_reach.last_proposal().quality_evaluations;
    EXPECT_EQ(out_of_reach.last_proposal().quality_evaluations,
              unbudgeted.last_proposal().quality_evaluations);
  }
  EXPECT_GT(refitting_evaluations, out_of_reach_evaluations + 30);
}

// Do no harm, measured: a plant that punishes every move away from u0 (the correction costs
// more than it saves) gets corrections only at the audit's own assemblies (every
// audit_period-th), whether it picks its arm before the model's fit or after; with the audit off
// no assembly is audited. The step reports say who held the rest back: on this plant the rules
// (innovations beyond the gate, unexplained surprises, an estimate beyond reach) hold most of
// them before the audit's verdict is asked, and the audit counts them in its uncorrected arm
// (the verdicts alone: do_no_harm_audit_test.cpp).
TEST(ActiveController, AuditsItsCorrectionAndDropsOneThatDoesHarm) {
  const RuggedTwin twin(RuggedTwinOptions{}, RandomStream(5));
  const VectorX offset = Eigen::Vector3d(0.05, -0.04, 0.03);
  const std::vector<AssemblyId> assemblies = twin.assemblies();
  for (const auto& [period, arm_first] :
       {std::pair{Index{10}, true}, std::pair{Index{10}, false}, std::pair{Index{0}, true}}) {
    ActiveController<RuggedTwin, Dynamic> controller(
        twin, RandomStream(6),
        ActiveOptions{.audit_period = period, .fit_at_audited_arm = arm_first});
    int corrected = 0;
    int audited = 0;
    int corrected_unaudited = 0;
    int held_by_audit = 0;
    for (int t = 0; t < 120; ++t) {
      const AssemblyId& x = assemblies[static_cast<std::size_t>(t) % assemblies.size()];
      const VectorX u = controller.propose(x);
      const double z = twin.quality(x, VectorX(u - offset)) + 5.0 * (u - twin.optimum(x)).norm();
      controller.observe(x, u, z);
      const ActiveStepReport& step = controller.last_step();
      expect_holds_explain_the_control(step, t);
      audited += step.audited ? 1 : 0;
      held_by_audit += step.held_by_audit ? 1 : 0;
      if (t >= 60) {
        corrected += step.corrected ? 1 : 0;
        corrected_unaudited += step.corrected && !step.audited ? 1 : 0;
      }
    }
    if (period > 0) {
      EXPECT_GT(audited, 10);
      EXPECT_LE(corrected, 60 / 10 + 1);
      EXPECT_EQ(corrected_unaudited, 0);
    } else {
      EXPECT_EQ(audited, 0);
      EXPECT_EQ(held_by_audit, 0);
    }
  }
}

// fit_at_audited_arm (the default): the audit picks its arm before the assembly's model is
// fitted, and the model is fitted where the plant will be under that arm if the estimate is
// right: at the twin-frame control u0 + (δû if corrected) − δû, so an assembly the audit leaves
// uncorrected is fitted at u0 − δû, not at u0. Probes priced by the model (regret_probe = 0), so
// that the centre does not hold the probe.
TEST(ActiveController, FitsEachModelWhereTheAuditsArmPutsThePlant) {
  const RuggedTwin twin(RuggedTwinOptions{}, RandomStream(5));
  const VectorX offset = Eigen::Vector3d(0.05, -0.04, 0.03);
  const std::vector<AssemblyId> assemblies = twin.assemblies();
  // The correction unbounded after a surprise (this plant surprises), so that the centre below
  // holds the whole estimate.
  const ActiveOptions options{.surprise_step_fraction = 0.0,
                              .regret_probe = 0.0,
                              .audit_period = 3,
                              .fit_at_audited_arm = true};
  ActiveController<RuggedTwin, Dynamic> controller(twin, RandomStream(6), options);
  const VectorX lower = twin.lower_bounds();
  const VectorX upper = twin.upper_bounds();
  const VectorX max_offset = options.max_offset_fraction * (upper - lower);
  std::array<int, 2> arms{};
  double uncorrected_estimate = 0.0;  // the largest |δû| the audit left uncorrected
  for (int t = 0; t < 150; ++t) {
    const AssemblyId& x = assemblies[static_cast<std::size_t>(t) % assemblies.size()];
    const VectorX u = controller.propose(x);
    const ActiveStepReport& step = controller.last_step();
    if (step.audited) {
      ++arms[step.corrected ? 1 : 0];
      const ProposalReport& proposal = controller.last_proposal();
      const VectorX estimate = proposal.default_control - proposal.individual_control;
      VectorX expected = proposal.individual_control.cwiseMax(lower).cwiseMin(upper);
      if (step.corrected) expected += estimate.cwiseMax(-max_offset).cwiseMin(max_offset);
      expected = (expected - estimate).cwiseMax(lower).cwiseMin(upper);
      EXPECT_LT((controller.model().center - expected).cwiseAbs().maxCoeff(), 1e-12)
          << "assembly " << t << ", corrected " << step.corrected;
      if (!step.corrected) uncorrected_estimate = std::max(uncorrected_estimate, estimate.norm());
    }
    const double z = twin.quality(x, VectorX(u - offset)) + 5.0 * (u - twin.optimum(x)).norm();
    controller.observe(x, u, z);
  }
  // Both arms were audited, and the uncorrected arm had an estimate to leave out.
  EXPECT_GT(arms[0], 3);
  EXPECT_GT(arms[1], 3);
  EXPECT_GT(uncorrected_estimate, 0.01);
}

// The audit compares its arms on pairs: an audited assembly and the one just before it, when
// that was audited in the other arm. Recomputed from the step reports of the harmful plant
// above, the pairs' regrets (z − z*)/z* are exactly the ones the controller keeps, ring slot by
// ring slot — nothing older, nothing unpaired, no pair across a gap.
TEST(ActiveController, PairsItsAuditedAssembliesOnlyAcrossAdjacentAssembliesOfDifferentArms) {
  const RuggedTwin twin(RuggedTwinOptions{}, RandomStream(5));
  const VectorX offset = Eigen::Vector3d(0.05, -0.04, 0.03);
  const std::vector<AssemblyId> assemblies = twin.assemblies();
  // Its estimates beyond the correction's reach applied, clamped, and no trial, whose first
  // surprise holds the estimate back: both make the audit's pairs.
  const ActiveOptions options{
      .clamp_beyond_reach = true, .trial_innovations = 0, .audit_period = 3, .audit_window = 4};
  ActiveController<RuggedTwin, Dynamic> controller(twin, RandomStream(6), options);
  const auto window = static_cast<std::size_t>(options.audit_window);
  std::array<std::vector<double>, 2> expected{std::vector<double>(window, 0.0),
                                              std::vector<double>(window, 0.0)};
  std::size_t pairs = 0;
  std::array<int, 2> arms{};
  bool previous_audited = false;
  bool previous_corrected = false;
  double previous_regret = 0.0;
  for (int t = 0; t < 600; ++t) {
    const AssemblyId& x = assemblies[static_cast<std::size_t>(t) % assemblies.size()];
    const VectorX u = controller.propose(x);
    const double z = twin.quality(x, VectorX(u - offset)) + 5.0 * (u - twin.optimum(x)).norm();
    controller.observe(x, u, z);
    const ActiveStepReport& step = controller.last_step();
    const double best = controller.last_proposal().optimal_quality;
    const double regret = (z - best) / best;
    if (step.audited) {
      ++arms[step.corrected ? 1 : 0];
      if (previous_audited && previous_corrected != step.corrected) {
        const std::size_t arm = step.corrected ? 1 : 0;
        expected[arm][pairs % window] = regret;
        expected[1 - arm][pairs % window] = previous_regret;
        ++pairs;
      }
    }
    previous_audited = step.audited;
    previous_corrected = step.corrected;
    previous_regret = regret;
  }
  // The scenario exercises it: both arms audited, pairs made, and the ring wrapped.
  ASSERT_GT(arms[0], 3);
  ASSERT_GT(arms[1], 3);
  ASSERT_GT(pairs, window);
  const nlohmann::json saved = controller.save()["audit_pairs"];
  EXPECT_EQ(saved["count"].get<std::size_t>(), pairs);
  for (std::size_t arm = 0; arm < 2; ++arm) {
    const auto kept = saved["regrets"][arm].get<std::vector<double>>();
    ASSERT_EQ(kept.size(), window);
    for (std::size_t i = 0; i < window; ++i) {
      EXPECT_DOUBLE_EQ(kept[i], expected[arm][i]) << "arm " << arm << ", slot " << i;
    }
  }
}

TEST(ActiveController, OptionsNameTheRuleTheyBreak) {
  EXPECT_EQ(ActiveOptions{.measurement_variance = -1.0}.validate(),
            "measurement_variance: value is -1; rule: must be finite and > 0");
  EXPECT_EQ(ActiveOptions{.max_offset_fraction = -0.1}.validate(),
            "max_offset_fraction: value is -0.1; rule: must lie in [0, 1]");
  EXPECT_EQ(ActiveOptions{.correction_step_fraction = -0.1}.validate(),
            "correction_step_fraction: value is -0.1; rule: must be finite and >= 0");
  EXPECT_EQ(ActiveOptions{.surprise_step_fraction = -0.25}.validate(),
            "surprise_step_fraction: value is -0.25; rule: must be finite and >= 0");
  EXPECT_EQ(ActiveOptions{.hold_after_surprises = 6}.validate(),
            "hold_after_surprises: value is 6; rule: must lie in [0, trajectory.change_window + "
            "3] = [0, 5]");
  EXPECT_EQ(ActiveOptions{.trial_innovations = -1}.validate(),
            "trial_innovations: value is -1; rule: must be >= 0");
  EXPECT_EQ(ActiveOptions{.surrogate = {.tolerance = 0.0}}.validate(),
            "surrogate.tolerance: value is 0; rule: must be finite and > 0");
  EXPECT_EQ(ActiveOptions{.relinearization_budget = -1.0}.validate(),
            "relinearization_budget: value is -1; rule: must be finite and >= 0");
  EXPECT_EQ(ActiveOptions{.relinearization_reach = -0.5}.validate(),
            "relinearization_reach: value is -0.5; rule: must be finite and > 0");
  // At 0 a refitted entry's τ² would be 0, and an entry of τ² = 0 is never refitted again.
  EXPECT_EQ(ActiveOptions{.relinearization_reach = 0.0}.validate(),
            "relinearization_reach: value is 0; rule: must be finite and > 0");
  EXPECT_EQ(
      ActiveOptions{.audit_period = 1}.validate(),
      "audit_period and audit_window: values are 1 and 10; rule: audit_period = 0 (no audit), or "
      "audit_period >= 2 and audit_window >= 3");
  EXPECT_EQ(ActiveOptions{.regret_probe = -0.1}.validate(),
            "regret_probe: value is -0.1; rule: must be finite and >= 0");
  EXPECT_EQ(ActiveOptions{.regret_window = 0}.validate(),
            "regret_window: value is 0; rule: must be >= 1");
  EXPECT_EQ(ActiveOptions{.audit_misfit = 0.5}.validate(),
            "audit_misfit: value is 0.5; rule: must be finite and >= 1");
  const test_support::AnalyticTwin twin = test_support::make_twin(2);
  EXPECT_THROW((ActiveController<test_support::AnalyticTwin, Dynamic>(
                   twin, RandomStream(1), ActiveOptions{.max_probe_fraction = 2.0})),
               InvalidArgumentError);
}

// --- snapshots (save / restore, SnapshotController) ------------------------------------------

static_assert(SnapshotController<ActiveController<CountingTwin, 3>>);
static_assert(SnapshotController<ActiveController<RuggedTwin, Dynamic>>);

// Assembly t of a drifting plant Q(x, u − δu*_t); every `other`-th assembly the cell applies
// another control than the proposal (0: never). Returns u_t and the whole state after the
// observation (save(): estimate, covariance, reports, estimator, streams) as text.
template <typename C, typename T>
std::pair<VectorX, std::string> active_snapshot_step(C& controller, const T& twin,
                                                     const std::vector<AssemblyId>& assemblies,
                                                     int t, bool propose = true, VectorX u = {},
                                                     int other = 0) {
  const AssemblyId& x = assemblies[static_cast<std::size_t>(t) % assemblies.size()];
  if (propose) u = controller.propose(x);
  if (other > 0 && t % other == 0) u.array() += 0.01;
  const double s = static_cast<double>(t);
  const VectorX offset = Eigen::Vector3d(0.1 * std::sin(0.05 * s), -0.08 + 0.002 * s, 0.05);
  controller.observe(x, typename C::ControlVector(u), twin.quality(x, VectorX(u - offset)));
  return {u, controller.save().dump()};
}

template <typename C, typename T>
void expect_active_restores(const T& twin, const std::vector<AssemblyId>& assemblies,
                            ActiveOptions options, int other) {
  for (const bool between : {false, true}) {
    // After an observation, or between a proposal and its observation.
    C copy(twin, RandomStream(8), options);
    for (int t = 0; t < 30; ++t) {
      (void)active_snapshot_step(copy, twin, assemblies, t, true, {}, other);
    }
    VectorX u;
    if (between) u = copy.propose(assemblies[30]);
    const nlohmann::json snapshot = nlohmann::json::parse(copy.save().dump());
    C restored(twin, RandomStream(8), options);
    restored.restore(snapshot);
    EXPECT_EQ(restored.save().dump(), snapshot.dump());
    for (int t = 30; t < 70; ++t) {
      const bool propose = !(between && t == 30);
      EXPECT_EQ(active_snapshot_step(copy, twin, assemblies, t, propose, u, other),
                active_snapshot_step(restored, twin, assemblies, t, propose, u, other))
          << "assembly " << t << (between ? ", restored between propose and observe" : "");
    }
  }
}

TYPED_TEST(ActiveControllerTest, ASnapshotRestoresItBitForBit) {
  const test_support::AnalyticTwin twin = test_support::make_twin(3);
  const CountingTwin counting(twin);
  expect_active_restores<TypeParam>(counting, twin.assemblies(), ActiveOptions{}, 0);
}

// The sigma-point mode (a twin that is not quadratic, its model errors not weighed), with
// controls other than the proposal observed now and then.
TEST(ActiveController, ASnapshotRestoresItsSigmaPointModeBitForBit) {
  const RuggedTwin twin(RuggedTwinOptions{}, RandomStream(5));
  expect_active_restores<ActiveController<RuggedTwin, Dynamic>>(
      twin, twin.assemblies(), ActiveOptions{.weigh_model_error = false}, 4);
  // Model errors weighed, relinearization and the audit.
  expect_active_restores<ActiveController<RuggedTwin, Dynamic>>(twin, twin.assemblies(),
                                                                ActiveOptions{}, 0);
}

// Each kept assembly's check (for the τ² of its refits) is in the snapshot: a snapshot without
// it, or with a negative one, is refused by name and leaves the state as it was.
TEST(ActiveController, RestoresTheChecksOfItsKeptAssemblies) {
  const RuggedPlant plant;
  ActiveController<RuggedTwin, Dynamic> controller(plant.twin, RandomStream(6));
  for (int t = 0; t < 12; ++t) plant.answer(controller, t, controller.propose(plant.assembly(t)));
  const nlohmann::json good = controller.save();
  ASSERT_FALSE(good["kept_assemblies"].empty());
  ActiveController<RuggedTwin, Dynamic> restored(plant.twin, RandomStream(7));
  const std::string state = restored.save().dump();
  nlohmann::json bad = good;
  bad["kept_assemblies"][0].erase("model_error");
  EXPECT_THAT([&] { restored.restore(bad); },
              ::testing::ThrowsMessage<InvalidArgumentError>(
                  ::testing::HasSubstr("kept_assemblies[0].model_error: field is missing")));
  bad = good;
  bad["kept_assemblies"][0]["model_error"] = -0.5;
  EXPECT_THAT([&] { restored.restore(bad); },
              ::testing::ThrowsMessage<InvalidArgumentError>(::testing::HasSubstr(
                  "kept_assemblies[0].model_error: value is -0.5; rule: must be >= 0")));
  EXPECT_EQ(restored.save().dump(), state);
  restored.restore(good);
  EXPECT_EQ(restored.save().dump(), good.dump());
}

TEST(ActiveController, RefusesABadSnapshotAndKeepsItsState) {
  const test_support::AnalyticTwin twin = test_support::make_twin(3);
  ActiveController<test_support::AnalyticTwin, Dynamic> tried(twin, RandomStream(8));
  ActiveController<test_support::AnalyticTwin, Dynamic> untouched(twin, RandomStream(8));
  ActiveController<test_support::AnalyticTwin, Dynamic> other(twin, RandomStream(9));
  const std::vector<AssemblyId> assemblies = twin.assemblies();
  for (int t = 0; t < 20; ++t) {
    (void)active_snapshot_step(tried, twin, assemblies, t);
    (void)active_snapshot_step(untouched, twin, assemblies, t);
    (void)active_snapshot_step(other, twin, assemblies, t);
  }
  const nlohmann::json good = other.save();
  const std::string state = tried.save().dump();
  // The estimator is restored after the probe: the probe goes back when the estimator's part
  // is refused.
  nlohmann::json bad = good;
  bad["estimator"].erase("prediction_misfit");
  EXPECT_THAT([&] { tried.restore(bad); },
              ::testing::ThrowsMessage<InvalidArgumentError>(
                  ::testing::HasSubstr("estimator.prediction_misfit: field is missing")));
  EXPECT_EQ(tried.save().dump(), state);
  bad = good;
  bad["estimator"]["history"][3]["quality"] = nullptr;  // NaN
  EXPECT_THROW(tried.restore(bad), NonFiniteError);
  bad = good;
  bad["recent_innovations"].erase(0);  // a ring of another size
  EXPECT_THROW(tried.restore(bad), DimensionMismatchError);
  bad = good;
  bad["recent_surprises"][2] = 1;  // not a boolean
  EXPECT_THAT([&] { tried.restore(bad); },
              ::testing::ThrowsMessage<InvalidArgumentError>(
                  ::testing::HasSubstr("recent_surprises[2]: is 1; rule: must be true or false")));
  bad = good;
  bad["recent_surprises"].erase(0);
  EXPECT_THROW(tried.restore(bad), DimensionMismatchError);
  bad = good;
  bad["plant_regrets"].erase(0);
  EXPECT_THROW(tried.restore(bad), DimensionMismatchError);
  bad = good;
  bad.erase("regret_count");
  EXPECT_THAT([&] { tried.restore(bad); },
              ::testing::ThrowsMessage<InvalidArgumentError>(
                  ::testing::HasSubstr("regret_count: field is missing")));
  EXPECT_EQ(tried.save().dump(), state);
  bad = good;
  bad["probe"]["format"] = "twincal.information_probe";
  EXPECT_THROW(tried.restore(bad), InvalidArgumentError);
  EXPECT_EQ(tried.save().dump(), state);
  for (int t = 20; t < 40; ++t) {
    EXPECT_EQ(active_snapshot_step(tried, twin, assemblies, t),
              active_snapshot_step(untouched, twin, assemblies, t));
  }
}

}  // namespace
}  // namespace twincal

// The active controller on twins whose Q² is not a quadratic (key_point_twin.hpp): contact,
// stiffening and kinks, one typed suite over the nonlinearities, with the paper's drift (eq. 15).
namespace twincal::active_controller_nonlinear_test {
namespace {

template <typename Kind>
class ActiveControllerOnNonlinearTwin : public ::testing::Test {};
using Kinds = ::testing::Types<ContactNonlinearity, StiffeningNonlinearity, KinkNonlinearity>;
TYPED_TEST_SUITE(ActiveControllerOnNonlinearTwin, Kinds);

struct Episode {
  double active = 0.0;    // mean (z − z*)/z*
  double baseline = 0.0;  // the same for u0 − δu* (no calibration)
  double error = 0.0;     // mean ‖δû − δu*‖ over the second half
  double offset = 0.0;    // mean ‖δu*‖ over the second half (the baseline's error)
  double evaluations = 0.0;
};

// A d = 3 key-point twin of `Kind` at strength 1 (its u0 searched), its assemblies, the paper's
// drift (eq. 15) drawn from `stream`'s substream "drift", and `stream` for the controllers.
template <typename Kind>
struct KeyPointScene {
  using Twin = SearchedOptimumTwin<KeyPointTwin<Kind>>;
  using Controller = ActiveController<Twin, 3>;

  KeyPointScene(std::uint64_t twin_seed, std::uint64_t stream_seed)
      : KeyPointScene(key_points(twin_seed), RandomStream(stream_seed)) {}

  std::vector<AssemblyId> assemblies;
  Twin twin;
  RandomStream stream;
  BouncingDrift<3> drift;

 private:
  KeyPointScene(KeyPointTwin<Kind> points, RandomStream controllers)
      : assemblies(points.assemblies()),
        twin(std::move(points), assemblies),
        stream(std::move(controllers)),
        drift(paper_drift(stream)) {}
  static KeyPointTwin<Kind> key_points(std::uint64_t seed) {
    KeyPointTwinOptions options;
    options.assemblies.dimension = 3;
    return KeyPointTwin<Kind>(options, RandomStream(seed));
  }
  static BouncingDrift<3> paper_drift(const RandomStream& stream) {
    RandomStream drift_stream = stream.substream("drift");
    return BouncingDrift<3>::random(3, drift_stream);
  }
};

// One episode of 100 assemblies at strength 1, d = 3, with the paper's drift; the models from
// the key points' deviations (the default) or from Q² alone, as for a twin that has no key points.
template <typename Kind>
Episode run(std::uint64_t seed, bool from_deviations) {
  KeyPointScene<Kind> scene(seed, seed + 1);
  const auto& twin = scene.twin;
  const std::vector<AssemblyId>& assemblies = scene.assemblies;
  BouncingDrift<3>& drift = scene.drift;
  ActiveOptions settings;
  settings.surrogate.from_deviations = from_deviations;
  typename KeyPointScene<Kind>::Controller controller(twin, scene.stream.substream("controller"),
                                                      settings);
  Episode episode;
  const std::size_t n = assemblies.size();
  for (std::size_t t = 0; t < n; ++t) {
    const AssemblyId& x = assemblies[t];
    drift.advance();
    const Vector<3> u = controller.propose(x);
    const double z = twin.quality(x, VectorX(u - drift.offset()));
    controller.observe(x, u, z);
    const double best = twin.optimal_quality(x);
    episode.active += (z - best) / best;
    episode.baseline += (twin.quality(x, VectorX(twin.optimum(x) - drift.offset())) - best) / best;
    episode.evaluations += static_cast<double>(controller.last_proposal().quality_evaluations);
    if (t >= n / 2) {
      episode.error += (controller.offset_estimate() - drift.offset()).norm();
      episode.offset += drift.offset().norm();
    }
  }
  const double count = static_cast<double>(n);
  episode.active /= count;
  episode.baseline /= count;
  episode.evaluations /= count;
  return episode;
}

// Two controllers that differ only in erring_probe_gain (1 and `gain`), run in lockstep on one
// episode of a d = 3 key-point twin with the paper's drift, until their controls first differ.
// Returns that assembly's probe norms (gain 1, gain) and whether the assembly before it had a model
// that erred; {0, 0, false} when they never differ.
struct FirstDifference {
  double probe = 0.0;
  double gained_probe = 0.0;
  bool last_model_erred = false;
};

template <typename Kind>
FirstDifference first_difference_of_the_probe_gain(double gain) {
  KeyPointScene<Kind> scene(5, 6);
  const auto& twin = scene.twin;
  BouncingDrift<3>& drift = scene.drift;
  ActiveOptions without;
  without.erring_probe_gain = 1.0;
  ActiveOptions with = without;
  with.erring_probe_gain = gain;
  using Controller = typename KeyPointScene<Kind>::Controller;
  Controller plain(twin, scene.stream.substream("controller"), without);
  Controller gained(twin, scene.stream.substream("controller"), with);
  bool erred = false;
  for (const AssemblyId& x : scene.assemblies) {
    drift.advance();
    const Vector<3> u = plain.propose(x);
    const Vector<3> v = gained.propose(x);
    if (u != v) {
      return {plain.last_step().probe_norm, gained.last_step().probe_norm, erred};
    }
    const double z = twin.quality(x, VectorX(u - drift.offset()));
    plain.observe(x, u, z);
    gained.observe(x, v, z);
    erred = plain.last_step().model_variance > 0.0;
  }
  return {};
}

// The gain acts only where the last model erred, and at most multiplies the probe by itself (the
// regret's floor may have raised the plain one, the largest probe may clip the gained one).
TEST(ActiveControllerOnContact, MultipliesTheProbeByTheGainOnlyWhereTheLastModelErred) {
  const FirstDifference first = first_difference_of_the_probe_gain<ContactNonlinearity>(2.0);
  ASSERT_GT(first.gained_probe, 0.0) << "the gain never changed a control";
  EXPECT_TRUE(first.last_model_erred);
  EXPECT_GT(first.gained_probe, first.probe);
  EXPECT_LE(first.gained_probe, 2.0 * first.probe * (1.0 + 1e-12));
}

TEST(ActiveControllerOnAQuadraticKeyPointTwin, IsUnchangedByTheProbeGain) {
  const FirstDifference first = first_difference_of_the_probe_gain<NoNonlinearity>(4.0);
  EXPECT_EQ(first.gained_probe, 0.0) << "a twin whose models pass their checks changed";
}

// Two controllers with settings `a` and `b`, run in lockstep on one episode of a d = 3 key-point
// twin with the paper's drift: the first assembly whose controls differ (-1: none), and how many
// changes of velocity each declared over the episode.
struct Lockstep {
  Index first_difference = -1;
  Index changes_a = 0;
  Index changes_b = 0;
};

template <typename Kind>
Lockstep in_lockstep(const ActiveOptions& a, const ActiveOptions& b, std::uint64_t seed) {
  KeyPointScene<Kind> scene(seed, seed + 1);
  const auto& twin = scene.twin;
  const std::vector<AssemblyId>& assemblies = scene.assemblies;
  BouncingDrift<3>& drift = scene.drift;
  using Controller = typename KeyPointScene<Kind>::Controller;
  Controller first(twin, scene.stream.substream("controller"), a);
  Controller second(twin, scene.stream.substream("controller"), b);
  Lockstep result;
  for (Index t = 0; t < std::ssize(assemblies); ++t) {
    const AssemblyId& x = assemblies[static_cast<std::size_t>(t)];
    drift.advance();
    const Vector<3> u = first.propose(x);
    const Vector<3> v = second.propose(x);
    if (u != v && result.first_difference < 0) result.first_difference = t;
    first.observe(x, u, twin.quality(x, VectorX(u - drift.offset())));
    second.observe(x, v, twin.quality(x, VectorX(v - drift.offset())));
    result.changes_a += first.last_step().velocity_change ? 1 : 0;
    result.changes_b += second.last_step().velocity_change ? 1 : 0;
  }
  return result;
}

// The change gate after the refit acts only where models err: on a twin whose models pass their
// checks no model is refitted, and the gate on the first fit is the gate as it was made. (The
// innovations' test, which only the test after the refit reads, is off in both.)
TEST(ActiveControllerOnAQuadraticKeyPointTwin, IsUnchangedByTheChangeTestAfterTheRefit) {
  ActiveOptions after_refit;
  after_refit.trajectory.innovation_window = 0;
  ActiveOptions as_fitted = after_refit;
  as_fitted.change_test_after_refit = false;
  for (const std::uint64_t seed : {5U, 21U}) {
    const Lockstep run = in_lockstep<NoNonlinearity>(after_refit, as_fitted, seed);
    EXPECT_EQ(run.first_difference, -1) << "a twin whose models pass their checks changed";
    EXPECT_EQ(run.changes_a, run.changes_b);
  }
}

// On contact, a gate consulted on each fit as it is made sees the misfit of models the fit has
// moved beyond their checks' reach, and restarts the estimator at it; tested after the refit, in
// the same units (min_erring_gate_unit 1, and the fit in units of σz², min_erring_fit_unit 1),
// it declares fewer changes of velocity (the paper's drift turns at most three times in 100
// assemblies). (With the fit in the plant's units, which returns to σz² for a few assemblies
// after an innovation it did not predict, the two count within one of each other on each seed.)
TEST(ActiveControllerOnContact, DeclaresFewerChangesWhenItTestsAfterTheRefit) {
  ActiveOptions after_refit;
  after_refit.trajectory.min_erring_gate_unit = 1.0;
  after_refit.trajectory.min_erring_fit_unit = 1.0;
  ActiveOptions as_fitted = after_refit;
  as_fitted.change_test_after_refit = false;
  Index refitted_changes = 0;
  Index as_fitted_changes = 0;
  for (const std::uint64_t seed : {5U, 21U, 37U}) {
    const Lockstep run = in_lockstep<ContactNonlinearity>(after_refit, as_fitted, seed);
    refitted_changes += run.changes_a;
    as_fitted_changes += run.changes_b;
  }
  EXPECT_LT(refitted_changes, as_fitted_changes);
}

// A refitted entry is used within relinearization_reach · h of its new centre, so its τ² is the
// model's error at that distance, below the one it was added with (at one standard deviation of
// P); no entry's τ² grows. Contact at d = 3, the paper's drift, 40 assemblies, the fit in units
// of σz² (min_erring_fit_unit 1): in the plant's units P is a hundred times tighter, the fit
// moves the entries within their stencils: after 100 assemblies of this scene one entry of the
// history has been refitted.
TEST(ActiveControllerOnContact, WeighsARefittedModelByItsErrorWhereTheFitUsesIt) {
  KeyPointScene<ContactNonlinearity> scene(11, 12);
  const auto& twin = scene.twin;
  const std::vector<AssemblyId>& assemblies = scene.assemblies;
  BouncingDrift<3>& drift = scene.drift;
  KeyPointScene<ContactNonlinearity>::Controller controller(
      twin, scene.stream.substream("controller"),
      ActiveOptions{.trajectory = {.min_erring_fit_unit = 1.0}});
  std::vector<double> added(40);  // τ² of each assembly's model as it joined the history, by time
  for (Index t = 0; t < std::ssize(added); ++t) {
    const AssemblyId& x = assemblies[static_cast<std::size_t>(t)];
    drift.advance();
    const Vector<3> u = controller.propose(x);
    added[static_cast<std::size_t>(t)] = controller.last_step().model_variance;
    controller.observe(x, u, twin.quality(x, VectorX(u - drift.offset())));
  }
  const nlohmann::json saved = controller.save();
  int lowered = 0;
  for (const nlohmann::json& entry : saved["estimator"]["history"]) {
    const double variance = entry["model_variance"].get<double>();
    const double before = added.at(entry["time"].get<std::size_t>());
    EXPECT_LE(variance, before) << entry["time"];
    lowered += variance < 0.5 * before ? 1 : 0;
  }
  EXPECT_GT(lowered, 0);
  for (const nlohmann::json& entry : saved["kept_assemblies"]) {
    EXPECT_GE(entry.at("model_error").get<double>(), 0.0) << entry["time"];
  }
}

// Over three seeded episodes: better than no calibration by a clear margin, within the budget
// of 4 (d + 1)² twin evaluations per assembly, and — except on contact — never lost (its
// estimate closer to the offset than no estimate, over the second half). On contact the
// estimate is still lost in about 1 episode of 10 (docs/reproduction.md, "Black-box twins"),
// so there the test asks only that the episodes are not lost on average. Both ways of fitting
// the models.
TYPED_TEST(ActiveControllerOnNonlinearTwin, BeatsNoCalibrationAndKeepsTheOffset) {
  for (const bool from_deviations : {true, false}) {
    double active = 0.0;
    double baseline = 0.0;
    double error = 0.0;
    double offset = 0.0;
    for (const std::uint64_t seed : {11U, 12U, 13U}) {
      const Episode episode = run<TypeParam>(seed, from_deviations);
      const std::string label = fmt::format("seed {}, from_deviations {}", seed, from_deviations);
      if constexpr (!std::is_same_v<TypeParam, ContactNonlinearity>) {
        EXPECT_LT(episode.error, episode.offset) << "lost, " << label;
      }
      EXPECT_LE(episode.evaluations, 4.0 * 16.0) << label;
      active += episode.active;
      baseline += episode.baseline;
      error += episode.error;
      offset += episode.offset;
    }
    EXPECT_LT(error, offset) << "from_deviations " << from_deviations;
    EXPECT_LT(active, 0.6 * baseline) << "from_deviations " << from_deviations;
  }
}

}  // namespace
}  // namespace twincal::active_controller_nonlinear_test
