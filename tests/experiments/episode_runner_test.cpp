#include "twincal/experiments/episode_runner.hpp"

#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "twincal/core/error.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/experiments/twin_cases.hpp"
#include "twincal/models/bouncing_drift.hpp"

namespace twincal {
namespace {

ExperimentConfig episode_config(Index d, const std::string& locators) {
  ExperimentConfig config;
  config.twin_case = TwinCase::analytic;
  config.analytic_dimension = d;
  config.locators = locators;
  config.assemblies = 30;
  config.runs = 2;
  return config;
}

TEST(RunEpisode, EveryControllerOfARunSeesTheSameAssembliesAndOffsets) {
  const ExperimentConfig config = episode_config(3, "ABC");
  const CaseTwin twin = make_case_twin(config);
  const EpisodeResult baseline = run_episode(twin, config, ControllerSpec::baseline(), 1);
  for (const ControllerSpec& spec :
       {ControllerSpec::default_controller(), ControllerSpec::lookahead(0.0),
        ControllerSpec::lookahead(1.0), ControllerSpec::nominal()}) {
    const EpisodeResult other = run_episode(twin, config, spec, 1);
    ASSERT_EQ(other.steps, baseline.steps) << spec.label();
    EXPECT_EQ(other.assemblies, baseline.assemblies) << spec.label();
    EXPECT_EQ(other.offset, baseline.offset) << spec.label();
    EXPECT_EQ(other.z_star, baseline.z_star) << spec.label();
    EXPECT_EQ(other.run_seed, baseline.run_seed);
  }
  const EpisodeResult next_run = run_episode(twin, config, ControllerSpec::baseline(), 0);
  EXPECT_NE(next_run.assemblies, baseline.assemblies);
  EXPECT_NE(next_run.offset, baseline.offset);
}

TEST(RunEpisode, IsDeterministic) {
  const ExperimentConfig config = episode_config(3, "ABC");
  const CaseTwin twin = make_case_twin(config);
  const EpisodeResult a = run_episode(twin, config, ControllerSpec::lookahead(0.5), 0);
  const EpisodeResult b = run_episode(twin, config, ControllerSpec::lookahead(0.5), 0);
  EXPECT_EQ(a.z, b.z);
  EXPECT_EQ(a.control, b.control);
  EXPECT_EQ(a.estimate, b.estimate);
  EXPECT_EQ(a.trace_p, b.trace_p);
  EXPECT_EQ(a.q_evaluations, b.q_evaluations);
}

// The baseline's episode rebuilt from the documented streams: order from "assembly_order"
// (Fisher–Yates), δu*_t from eq. (15) with the direction from "drift", z_t = Q_S(x, u0 − δu*_t).
TEST(RunEpisode, BaselineFollowsTheDocumentedProtocol) {
  ExperimentConfig config = episode_config(2, "A,B");
  const CaseTwin twin = make_case_twin(config);
  const EpisodeResult result = run_episode(twin, config, ControllerSpec::baseline(), 3);
  const RandomStream run = RandomStream(config.seed).substream("run").substream(3);
  EXPECT_EQ(result.run_seed, run.seed());

  std::vector<AssemblyId> order = twin.assemblies();
  RandomStream shuffle = run.substream("assembly_order");
  for (std::size_t i = order.size(); i > 1; --i) {
    std::swap(order[i - 1], order[shuffle.uniform_int<std::size_t>(0, i - 1)]);
  }
  RandomStream drift_stream = run.substream("drift");
  BouncingDrift<Dynamic> drift = BouncingDrift<Dynamic>::random(2, drift_stream);
  double residual = 0.0;
  double error = 0.0;
  ASSERT_EQ(result.steps, 30);
  for (Index t = 0; t < 30; ++t) {
    const AssemblyId& x = order[static_cast<std::size_t>(t)];
    drift.advance();
    EXPECT_EQ(result.assemblies[static_cast<std::size_t>(t)], x);
    EXPECT_EQ(Eigen::VectorXd(result.offset.col(t)), drift.offset());
    const Eigen::VectorXd u0 = twin.optimum(x);
    EXPECT_EQ(Eigen::VectorXd(result.control.col(t)), u0);
    const Eigen::VectorXd shifted = u0 - drift.offset();
    const double z = twin.plant_quality(x, shifted);
    EXPECT_EQ(result.z(t), z);
    EXPECT_EQ(result.q_evaluations(t), 0.0);
    EXPECT_TRUE(std::isnan(result.trace_p(t)));
    residual += (z - twin.optimal_quality(x)) / twin.optimal_quality(x);
    error += drift.offset().norm();  // the baseline's δû is 0
  }
  EXPECT_DOUBLE_EQ(result.relative_residual, residual / 30.0);
  EXPECT_DOUBLE_EQ(result.estimation_error, error / 30.0);
  EXPECT_FALSE(result.diverged());
}

TEST(RunEpisode, AssessesTheLostRuleOnItsTrace) {
  const ExperimentConfig config = episode_config(3, "ABC");
  const CaseTwin twin = make_case_twin(config);
  for (const ControllerSpec& spec :
       {ControllerSpec::baseline(), ControllerSpec::nominal(), ControllerSpec::default_controller(),
        ControllerSpec::lookahead(0.5)}) {
    const EpisodeResult result = run_episode(twin, config, spec, 1);
    EpisodeResult again = result;
    assess_lost(again);
    EXPECT_EQ(result.estimate_error_second_half, again.estimate_error_second_half) << spec.label();
    EXPECT_EQ(result.offset_norm_second_half, again.offset_norm_second_half) << spec.label();
    EXPECT_EQ(result.lost, again.lost) << spec.label();
    EXPECT_FALSE(std::isnan(result.offset_norm_second_half)) << spec.label();
    if (!spec.estimates()) {
      // No correction: the yardstick itself, never lost.
      EXPECT_EQ(result.estimate_error_second_half, result.offset_norm_second_half);
      EXPECT_FALSE(result.lost) << spec.label();
    }
  }
}

TEST(RunEpisode, CountsTheFiltersEvaluations) {
  const ExperimentConfig config = episode_config(3, "ABC");
  const CaseTwin twin = make_case_twin(config);
  // The default controller's update evaluates the 2d + 1 sigma points of the UKF.
  const EpisodeResult result = run_episode(twin, config, ControllerSpec::default_controller(), 0);
  EXPECT_EQ(result.q_evaluations, Eigen::VectorXd::Constant(30, 7.0));
  // The w-controller scores its surviving candidates at every sigma point (at most 32 x 7) and
  // commits without evaluating.
  const EpisodeResult w = run_episode(twin, config, ControllerSpec::lookahead(0.5), 0);
  for (Index t = 0; t < w.steps; ++t) {
    EXPECT_GE(w.q_evaluations(t), 7.0);
    EXPECT_LE(w.q_evaluations(t), 32.0 * 7.0);
    EXPECT_EQ(std::fmod(w.q_evaluations(t), 7.0), 0.0);
  }
  // One one-locator w-controller per locator: each scores at most 2^3 = 8 candidates at its 3
  // sigma points and updates afresh at 3, so 3 · 3 to 3 · (8 · 3 + 3) per assembly.
  const EpisodeResult components = run_episode(twin, config, ControllerSpec::per_component(0.5), 0);
  ASSERT_GT(components.steps, 0);
  for (Index t = 0; t < components.steps; ++t) {
    EXPECT_GE(components.q_evaluations(t), 9.0) << t;
    EXPECT_LE(components.q_evaluations(t), 81.0) << t;
  }
  // A candidate cap bounds the w-controller's scoring.
  ExperimentConfig capped = config;
  capped.candidate_cap = 2;
  const EpisodeResult few = run_episode(twin, capped, ControllerSpec::lookahead(0.5), 0);
  for (Index t = 0; t < few.steps; ++t) EXPECT_LE(few.q_evaluations(t), 2.0 * 7.0) << t;
  // The active controller fits its model (d + 1 = 4, or (d + 1)(d + 2)/2 = 10 when it refits H)
  // and checks it at 2 points: 6 or 12 per assembly, within 4 (d + 1)² = 64.
  const EpisodeResult active = run_episode(twin, config, ControllerSpec::active(), 0);
  EXPECT_EQ(active.q_evaluations(0), 12.0);
  for (Index t = 1; t < active.steps; ++t) {
    EXPECT_TRUE(active.q_evaluations(t) == 6.0 || active.q_evaluations(t) == 12.0) << t;
  }
}

TEST(RunEpisode, RefusesACandidateCountBeyondTheLimitNamingTheCap) {
  // d = 21: the paper's 2^(2+d) = 2^23 candidates per assembly pass the 2^22 limit.
  ExperimentConfig config = episode_config(21, "all");
  const CaseTwin twin = make_case_twin(config);
  try {
    (void)run_episode(twin, config, ControllerSpec::lookahead(1.0), 0);
    FAIL() << "no error";
  } catch (const InvalidArgumentError& error) {
    EXPECT_EQ(error.argument(), "candidates");
    EXPECT_NE(std::string(error.what()).find("candidate_cap"), std::string::npos) << error.what();
  }
  config.candidate_cap = 64;
  EXPECT_EQ(run_episode(twin, config, ControllerSpec::lookahead(1.0), 0).steps, config.assemblies);
}

TEST(RunEpisode, DetectsDivergenceAndStopsOrContinuesAsConfigured) {
  ExperimentConfig config = episode_config(3, "A");
  config.divergence_threshold = 1e-12;  // every estimate is "far" from the offset
  const CaseTwin twin = make_case_twin(config);
  const EpisodeResult stopped = run_episode(twin, config, ControllerSpec::lookahead(1.0), 0);
  EXPECT_EQ(stopped.diverged_at, 0);
  EXPECT_EQ(stopped.steps, 1);
  EXPECT_DOUBLE_EQ(stopped.estimation_error,
                   std::abs(stopped.estimate(0, 0) - stopped.offset(0, 0)));
  config.stop_on_divergence = false;
  const EpisodeResult continued = run_episode(twin, config, ControllerSpec::lookahead(1.0), 0);
  EXPECT_EQ(continued.diverged_at, 0);
  EXPECT_EQ(continued.steps, 30);
  EXPECT_TRUE(continued.failure.empty());
}

TEST(RunEpisode, PlantNoiseComesFromTheRunsNoiseStream) {
  ExperimentConfig config = episode_config(3, "B");
  const CaseTwin twin = make_case_twin(config);
  const EpisodeResult quiet = run_episode(twin, config, ControllerSpec::baseline(), 0);
  config.plant_noise_variance = 1e-4;
  const EpisodeResult noisy = run_episode(twin, config, ControllerSpec::baseline(), 0);
  RandomStream noise =
      RandomStream(config.seed).substream("run").substream(0).substream("measurement_noise");
  for (Index t = 0; t < 30; ++t) {
    EXPECT_NEAR(noisy.z(t) - quiet.z(t), 1e-2 * noise.normal(), 1e-12);
  }
}

TEST(RunEpisode, EveryFilterSamplerAndLossRunsInEveryDimensionClass) {
  for (const auto& [d, locators] :
       {std::pair<Index, const char*>{3, "C"}, {3, "ABC"}, {4, "all"}}) {
    for (const FilterScheme filter :
         {FilterScheme::merwe, FilterScheme::julier, FilterScheme::cubature,
          FilterScheme::fifth_degree, FilterScheme::simplex}) {
      ExperimentConfig config = episode_config(d, locators);
      config.assemblies = 5;
      config.filter = filter;
      config.kappa = filter == FilterScheme::julier ? 1.0 : 0.0;
      const CaseTwin twin = make_case_twin(config);
      const EpisodeResult result = run_episode(twin, config, ControllerSpec::lookahead(0.5), 0);
      EXPECT_EQ(result.steps, 5) << to_string(filter) << " d=" << d << ": " << result.failure;
      EXPECT_TRUE(std::isfinite(result.relative_residual));
    }
    for (const CandidateSampler sampler :
         {CandidateSampler::halton, CandidateSampler::random, CandidateSampler::latin_hypercube}) {
      for (const ExplorationKind loss : {ExplorationKind::weighted_trace, ExplorationKind::log_det,
                                         ExplorationKind::max_eigenvalue}) {
        ExperimentConfig config = episode_config(d, locators);
        config.assemblies = 5;
        config.sampler = sampler;
        config.exploration = loss;
        config.candidates = 10;
        const CaseTwin twin = make_case_twin(config);
        const EpisodeResult result = run_episode(twin, config, ControllerSpec::lookahead(0.7), 0);
        EXPECT_EQ(result.steps, 5)
            << to_string(sampler) << "/" << to_string(loss) << ": " << result.failure;
      }
    }
  }
}

}  // namespace
}  // namespace twincal
