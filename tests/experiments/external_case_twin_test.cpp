#include "twincal/experiments/external_case_twin.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <limits>
#include <memory>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "twincal/core/error.hpp"
#include "twincal/experiments/episode_runner.hpp"
#include "twincal/experiments/episode_trace.hpp"
#include "twincal/experiments/experiment_config.hpp"
#include "twincal/experiments/experiment_runner.hpp"
#include "twincal/experiments/result_store.hpp"
#include "twincal/experiments/searched_optima_file.hpp"
#include "twincal/experiments/twin_cases.hpp"

namespace twincal {
namespace {

using ::testing::HasSubstr;

// examples/external_twin/minimal_twin.py: Q = sqrt(q0 + Σ w_i (u_i − a_i)²), so u0 = a and
// z* = sqrt(q0), both known in closed form from the part indices.
ExternalTwinSettings minimal_twin(Index workers) {
  ExternalTwinSettings settings;
  settings.command = {"python3",
                      TWINCAL_TEST_DATA_DIR "/../../examples/external_twin/minimal_twin.py"};
  settings.locators = {"A", "B", "C"};
  settings.lower_bounds = {-1.0, -1.0, -1.0};
  settings.upper_bounds = {1.0, 1.0, 1.0};
  settings.upper_parts = 2;
  settings.lower_parts = 3;
  settings.workers = workers;
  settings.optimum_global_evaluations = 300;
  settings.optimum_local_evaluations = 300;
  return settings;
}

TEST(ExternalCaseTwin, FindsEveryAssemblysOptimumWithTheSameResultForAnyNumberOfWorkers) {
  const ExternalCaseTwin one(minimal_twin(1));
  const ExternalCaseTwin three(minimal_twin(3));
  ASSERT_EQ(one.assemblies().size(), 6U);
  EXPECT_EQ(one.locator_names(), (std::vector<std::string>{"A", "B", "C"}));
  for (const AssemblyId& x : one.assemblies()) {
    const double q0 = 0.04 + 0.01 * static_cast<double>((3 * x.upper + 5 * x.lower) % 7);
    EXPECT_NEAR(one.optimal_quality(x), std::sqrt(q0), 1e-9) << fmt::format("{}", x);
    for (Index i = 0; i < 3; ++i) {
      const double best =
          0.2 * std::sin(1.7 * static_cast<double>(x.upper) + 0.9 * static_cast<double>(x.lower) +
                         static_cast<double>(i));
      EXPECT_NEAR(one.optimum(x)(i), best, 1e-4) << fmt::format("{}", x);
    }
    EXPECT_EQ(one.optimum(x), three.optimum(x));
    EXPECT_EQ(one.optimal_quality(x), three.optimal_quality(x));
  }
  EXPECT_EQ(one.search_evaluations(), three.search_evaluations());
  EXPECT_GT(one.search_evaluations(), 6U * 300U);
  // Batches go through the pool, in order.
  MatrixX controls(3, 4);
  controls.setZero();
  controls.col(1) = one.optimum({1, 2});
  VectorX out(4);
  three.quality_batch({1, 2}, controls, out);
  EXPECT_DOUBLE_EQ(out(1), three.optimal_quality({1, 2}));
  EXPECT_EQ(out(0), one.quality({1, 2}, controls.col(0)));
}

// An example twin of examples/external_twin (`script` D = 3 SEED) with `key_points` key points:
// their deviations have its quality as their RMS, and its Q² is not a quadratic in u — a
// quadratic's second difference along a locator is the same everywhere to rounding, and along
// locator A (−0.8 … 0.8, the others at 0) the twin's span more than the smallest's size.
void expect_key_points_and_not_quadratic(const std::string& script, const std::string& seed,
                                         Index key_points) {
  ExternalTwinSettings settings = minimal_twin(1);
  settings.command = {"python3", TWINCAL_TEST_DATA_DIR "/../../examples/external_twin/" + script,
                      "3", seed};
  settings.key_points = key_points;
  const ExternalCaseTwin twin(settings);
  ASSERT_EQ(twin.key_point_count(), key_points);
  const AssemblyId x{1, 2};
  constexpr Index count = 41;
  MatrixX controls = MatrixX::Zero(3, count);
  for (Index c = 0; c < count; ++c) {
    controls(0, c) = -0.8 + 1.6 * static_cast<double>(c) / static_cast<double>(count - 1);
  }
  VectorX qualities(count);
  twin.quality_batch(x, controls, qualities);
  MatrixX deviations(key_points, count);
  twin.deviations_batch(x, controls, deviations);
  double smallest = std::numeric_limits<double>::infinity();
  double largest = 0.0;
  for (Index c = 0; c < count; ++c) {
    EXPECT_NEAR(deviations.col(c).norm() / std::sqrt(static_cast<double>(key_points)), qualities(c),
                1e-12)
        << script << " " << c;
    if (c == 0 || c + 1 == count) continue;
    const double second = qualities(c - 1) * qualities(c - 1) - 2.0 * qualities(c) * qualities(c) +
                          qualities(c + 1) * qualities(c + 1);
    smallest = std::min(smallest, second);
    largest = std::max(largest, second);
  }
  EXPECT_GT(largest - smallest, std::abs(smallest)) << script;
}

// examples/external_twin/gap_twin.py (docs/external.md, "A twin with closing gaps"): 60 key
// points; the gaps' second differences span a factor of 3.2 along the line.
TEST(ExternalCaseTwin, TheGapTwinExampleAnswersItsKeyPointsAndIsNotQuadratic) {
  expect_key_points_and_not_quadratic("gap_twin.py", "4242", 60);
}

// examples/external_twin/clamp_twin.py (docs/external.md, "A twin with clamps"): 50 key points;
// the clamps make Q² concave between them, so its second differences change sign.
TEST(ExternalCaseTwin, TheClampTwinExampleAnswersItsKeyPointsAndIsNotQuadratic) {
  expect_key_points_and_not_quadratic("clamp_twin.py", "5151", 50);
}

TEST(ExternalCaseTwin, RegistersScannedPartsOnceAndSearchesTheirOptimum) {
  ExternalCaseTwin twin(minimal_twin(2));
  const std::uint64_t searched = twin.search_evaluations();
  const nlohmann::json parts = {{"upper", nlohmann::json::array({0.25, 0.5})},
                                {"lower", nlohmann::json::array({1.5})}};
  const AssemblyId x = twin.add_scanned(parts);
  EXPECT_EQ(x, scanned_assembly(0));
  EXPECT_EQ(scanned_index(x), 0);
  EXPECT_EQ(twin.assembly_json(x), (nlohmann::json{{"parts", parts}}));
  // The minimal twin's closed form with U = 0.75, L = 1.5: q0 = 0.04 + 0.01·(9.75 mod 7).
  EXPECT_NEAR(twin.optimal_quality(x), std::sqrt(0.04 + 0.01 * 2.75), 1e-9);
  for (Index i = 0; i < 3; ++i) {
    EXPECT_NEAR(twin.optimum(x)(i), 0.2 * std::sin(1.7 * 0.75 + 0.9 * 1.5 + static_cast<double>(i)),
                1e-4);
  }
  const std::uint64_t after_one = twin.search_evaluations();
  EXPECT_GT(after_one, searched);
  // The same parts again: the same id, no new search; other parts: the next id.
  EXPECT_EQ(twin.add_scanned(parts), x);
  EXPECT_EQ(twin.search_evaluations(), after_one);
  EXPECT_EQ(twin.add_scanned(nlohmann::json{{"upper", nlohmann::json::array({0.0})},
                                            {"lower", nlohmann::json::array({0.0})}}),
            scanned_assembly(1));
  // Parts the program cannot evaluate: a typed failure, and nothing registered.
  EXPECT_THROW((void)twin.add_scanned(nlohmann::json{{"upper", "scan.csv"}}), ExternalTwinError);
  EXPECT_EQ(twin.scanned_count(), 2);
  try {
    (void)twin.optimum(scanned_assembly(2));
    FAIL() << "an unregistered scanned assembly was accepted";
  } catch (const InvalidArgumentError& error) {
    EXPECT_THAT(error.what(), HasSubstr("assembly: scanned assembly 2 is unknown; rule: 2 "
                                        "scanned assemblies are registered"));
  }
}

TEST(ExternalCaseTwin, RefusesAnUnknownAssemblyAndInvalidSettings) {
  const ExternalCaseTwin twin(minimal_twin(1));
  try {
    (void)twin.optimum({2, 0});
    FAIL() << "an unknown assembly was accepted";
  } catch (const InvalidArgumentError& error) {
    EXPECT_THAT(error.what(), HasSubstr("assembly: (upper 2, lower 0) is unknown; rule: parts "
                                        "within 2 × 3"));
  }
  ExternalTwinSettings bad = minimal_twin(1);
  bad.upper_bounds = {1.0, 1.0};
  EXPECT_THAT(bad.validate().value_or(""),
              HasSubstr("lower_bounds and upper_bounds: values are 3 and 2; rule: one entry per "
                        "locator (3) each"));
  bad = minimal_twin(1);
  bad.lower_bounds[1] = 1.0;
  EXPECT_THAT(bad.validate().value_or(""), HasSubstr("bounds of B: value is [1, 1]; rule: finite"));
  bad = minimal_twin(0);
  EXPECT_THAT(bad.validate().value_or(""),
              HasSubstr("workers: value is 0; rule: must lie in [1, 256]"));
  EXPECT_THROW(ExternalCaseTwin{bad}, InvalidArgumentError);
}

TEST(ExternalTwinSettings, GoWithTheExternalCaseAndOnlyWithIt) {
  ExperimentConfig config;
  config.twin_case = TwinCase::external;
  EXPECT_THAT(config.validate().value_or(""),
              HasSubstr("case and external_twin: values are external and unset; rule: "
                        "external_twin is given with the external case and only with it"));
  config.external_twin = minimal_twin(2);
  // More episodes' assemblies than its 2 × 3 pairs: refused before any twin is started, by the
  // study (not by validate(): twincal serve takes the same config and runs no episodes).
  config.assemblies = 7;
  EXPECT_EQ(config.validate(), std::nullopt);
  EXPECT_THAT(episode_assemblies_problem(config).value_or(""),
              HasSubstr("assemblies: value is 7; rule: must be <= the external twin's "
                        "upper_parts × lower_parts = 6"));
  ResultStore store(std::filesystem::temp_directory_path() / "twincal-assemblies-check");
  EXPECT_THROW((void)run_experiments(std::vector<ExperimentGroup>{{config}}, store, RunOptions{}),
               InvalidArgumentError);
  config.assemblies = 6;
  EXPECT_EQ(episode_assemblies_problem(config), std::nullopt);
  config.twin_case = TwinCase::body;
  EXPECT_THAT(config.validate().value_or(""),
              HasSubstr("case and external_twin: values are body and set"));
  // The pool's size does not define the episodes, the program does.
  config.twin_case = TwinCase::external;
  ExperimentConfig more_workers = config;
  more_workers.external_twin->workers = 7;
  more_workers.external_twin->optima_file = "searched_once.json";  // where u0 is kept, likewise
  EXPECT_EQ(episode_defining_json(config), episode_defining_json(more_workers));
  more_workers.external_twin->command.back() = "other_twin.py";
  EXPECT_NE(episode_defining_json(config), episode_defining_json(more_workers));
  // key_points and optimum_seed define the episodes only where a least-squares search uses them.
  ExperimentConfig with_deviations = config;
  with_deviations.external_twin->key_points = 4;
  with_deviations.external_twin->optimum_seed = 7;
  EXPECT_EQ(episode_defining_json(config), episode_defining_json(with_deviations));
  with_deviations.external_twin->optimum_method = "least_squares";
  with_deviations.external_twin->optimum_budget = 32;
  ExperimentConfig other_seed = with_deviations;
  other_seed.external_twin->optimum_seed = 8;
  EXPECT_NE(episode_defining_json(with_deviations), episode_defining_json(other_seed));
}

// The budgeted search (optimum_budget): BOBYQA alone, the first row and column of assemblies
// from the centre with 2B evaluations, the others from the additive warm start with B. On the
// minimal twin (a separable quadratic under the root) it finds the exact optimum within the
// budget, and the result does not depend on the number of workers. Its optimum is not additive
// in the parts (a = 0.2 sin(1.7 i + 0.9 j + k)), so the warm start is only near it: with
// B = (d + 1)² = 16 one assembly ended 3 % above z*, with 24 at 4e-5, with 2 (d + 1)² = 32
// every one at round-off (measured).
TEST(ExternalCaseTwin, BudgetedSearchFindsTheOptimumWithinItsBudget) {
  ExternalTwinSettings settings = minimal_twin(1);
  settings.optimum_budget = 32;  // 2 (d + 1)²
  const ExternalCaseTwin one(settings);
  settings.workers = 3;
  const ExternalCaseTwin three(settings);
  // 2 × 3 assemblies: (0, 0), (0, 1), (0, 2), (1, 0) in phase 0, (1, 1), (1, 2) in phase 1.
  EXPECT_LE(one.search_evaluations(), 4U * 64U + 2U * 32U);
  EXPECT_EQ(one.search_evaluations(), three.search_evaluations());
  for (const AssemblyId& x : one.assemblies()) {
    const double q0 = 0.04 + 0.01 * static_cast<double>((3 * x.upper + 5 * x.lower) % 7);
    EXPECT_NEAR(one.optimal_quality(x), std::sqrt(q0), 1e-6 * std::sqrt(q0))
        << fmt::format("{}", x);
    EXPECT_EQ(one.optimum(x), three.optimum(x));
  }
  settings.optimum_budget = 7;  // < 2d + 2
  EXPECT_THAT(settings.validate().value_or(""),
              HasSubstr("optimum_budget: value is 7; rule: 0 or >= 2d + 2 = 8"));
  nlohmann::json json = settings;
  json["optimum_budget"] = 16.5;
  EXPECT_THROW((void)json.get<ExternalTwinSettings>(), InvalidArgumentError);
}

// optimum_method "trust_region": the same budgets in batches (one request per round, to one
// worker). On the minimal twin (Q² a quadratic) it reaches z* in far fewer requests than
// evaluations, whatever the number of workers; the method is validated by name.
TEST(ExternalCaseTwin, TrustRegionSearchFindsTheOptimumInBatches) {
  ExternalTwinSettings settings = minimal_twin(1);
  settings.optimum_budget = 32;
  settings.optimum_method = "trust_region";
  const ExternalCaseTwin one(settings);
  settings.workers = 3;
  const ExternalCaseTwin three(settings);
  EXPECT_LE(one.search_evaluations(), 4U * 64U + 2U * 32U);
  EXPECT_EQ(one.search_evaluations(), three.search_evaluations());
  EXPECT_LT(one.search_requests() * 3, one.search_evaluations());
  EXPECT_EQ(one.search_requests(), three.search_requests());
  for (const AssemblyId& x : one.assemblies()) {
    const double q0 = 0.04 + 0.01 * static_cast<double>((3 * x.upper + 5 * x.lower) % 7);
    EXPECT_NEAR(one.optimal_quality(x), std::sqrt(q0), 1e-6 * std::sqrt(q0))
        << fmt::format("{}", x);
    EXPECT_EQ(one.optimum(x), three.optimum(x));
  }
  // One assembly (no other search in flight): its rounds spread over the three workers, with
  // the same result as on one.
  settings.upper_parts = 1;
  settings.lower_parts = 1;
  const ExternalCaseTwin alone(settings);
  settings.workers = 1;
  const ExternalCaseTwin alone_on_one(settings);
  EXPECT_EQ(alone.optimum({0, 0}), alone_on_one.optimum({0, 0}));
  EXPECT_EQ(alone.optimum({0, 0}), one.optimum({0, 0}));
  EXPECT_EQ(alone.search_requests(), alone_on_one.search_requests());
  settings.optimum_method = "powell";
  EXPECT_THAT(settings.validate().value_or(""),
              HasSubstr("optimum_method: value is powell; rule: must be bobyqa, trust_region, "
                        "least_squares or least_squares_speculative"));
  nlohmann::json json = settings;
  json["optimum_method"] = "trust_region";
  EXPECT_EQ(json.get<ExternalTwinSettings>().optimum_method, "trust_region");
}

// The minimal twin on one worker with its 4 key points' deviations, u0 searched by least squares
// within a budget of 32 (64 for the first row and column).
ExternalTwinSettings least_squares_twin() {
  ExternalTwinSettings settings = minimal_twin(1);
  settings.optimum_budget = 32;
  settings.optimum_method = "least_squares";
  settings.key_points = 4;
  return settings;
}

// optimum_method "least_squares_speculative": each start and step comes with its Jacobian's
// stencil, d + 1 controls in one request, so the same optima in fewer requests; like
// least_squares it needs the deviations, and the restarts' seed identifies its results.
TEST(ExternalCaseTwin, SpeculativeLeastSquaresSearchFindsTheOptimaInFewerRequests) {
  ExternalTwinSettings settings = least_squares_twin();
  const ExternalCaseTwin plain(settings);
  settings.optimum_method = "least_squares_speculative";
  const ExternalCaseTwin speculative(settings);
  EXPECT_LT(speculative.search_requests(), plain.search_requests());
  EXPECT_LE(speculative.search_evaluations(), 4U * 64U + 2U * 32U);
  for (const AssemblyId& x : plain.assemblies()) {
    EXPECT_NEAR(speculative.optimal_quality(x), plain.optimal_quality(x),
                1e-9 * plain.optimal_quality(x))
        << fmt::format("{}", x);
  }
  EXPECT_TRUE(result_defining_json(settings).contains("optimum_seed"));
  settings.key_points = 0;
  EXPECT_THAT(settings.validate().value_or(""),
              HasSubstr("optimum_method: value is least_squares_speculative; rule: "
                        "least_squares needs a program that answers its key points' deviations"));
}

// optimum_start_command: each assembly's budgeted search starts from the optimum a fast start
// twin's full search found. Here the start twin is the same program, so its optimum is z*'s own
// and a budget of 2d + 2 = 8 keeps it, pairs and scanned assemblies alike, where the same budget
// from the centre and the additive warm start does not reach z*; the start twin's evaluations
// are its own. It needs a budgeted search, and it identifies the results it starts.
TEST(ExternalCaseTwin, StartsEachBudgetedSearchFromTheStartTwinsOptimum) {
  ExternalTwinSettings settings = minimal_twin(2);
  settings.optimum_budget = 8;
  const ExternalCaseTwin unstarted(settings);
  settings.optimum_start_command = settings.command;
  const ExternalCaseTwin started(settings);
  EXPECT_GT(started.start_search_evaluations(), 6U * 300U);
  EXPECT_EQ(unstarted.start_search_evaluations(), 0U);
  EXPECT_LE(started.search_evaluations(), 6U * 8U);
  double unstarted_worst = 0.0;
  for (const AssemblyId& x : started.assemblies()) {
    const double z_star =
        std::sqrt(0.04 + 0.01 * static_cast<double>((3 * x.upper + 5 * x.lower) % 7));
    EXPECT_NEAR(started.optimal_quality(x), z_star, 1e-9 * z_star) << fmt::format("{}", x);
    unstarted_worst = std::max(unstarted_worst, unstarted.optimal_quality(x) / z_star - 1.0);
  }
  EXPECT_GT(unstarted_worst, 1e-6);
  const nlohmann::json parts = {{"upper", nlohmann::json::array({0.25, 0.5})},
                                {"lower", nlohmann::json::array({1.5})}};
  ExternalCaseTwin scanning(settings);
  const std::uint64_t before = scanning.search_evaluations();
  EXPECT_NEAR(scanning.optimal_quality(scanning.add_scanned(parts)), std::sqrt(0.04 + 0.01 * 2.75),
              1e-9);
  EXPECT_LE(scanning.search_evaluations() - before, 8U);
  EXPECT_EQ(result_defining_json(settings)["optimum_start_command"], settings.command);
  EXPECT_FALSE(result_defining_json(minimal_twin(2)).contains("optimum_start_command"));
  const nlohmann::json json = settings;
  EXPECT_EQ(json.get<ExternalTwinSettings>().optimum_start_command, settings.command);
  nlohmann::json one_string = json;
  one_string["optimum_start_command"] = "python3  fast.py --coarse";
  EXPECT_EQ(one_string.get<ExternalTwinSettings>().optimum_start_command,
            (std::vector<std::string>{"python3", "fast.py", "--coarse"}));
  settings.optimum_budget = 0;
  EXPECT_THAT(settings.validate().value_or(""),
              HasSubstr("optimum_start_command: value is [python3, "));
  EXPECT_THAT(settings.validate().value_or(""),
              HasSubstr("needs a budgeted search (optimum_budget > 0 = 0)"));
}

// optimum_method "least_squares": the program's key points' deviations (the minimal twin
// answers its 4), Levenberg–Marquardt on them. Its deviations are affine in u, so the first step
// lands on the optimum; the restarts, seeded by optimum_seed and the assembly, come back to it.
// Same result for any number of workers, through the pool and on one worker, and the deviations
// are the twin's too (TwinWithDeviations).
TEST(ExternalCaseTwin, LeastSquaresSearchFindsTheOptimumFromTheProgramsDeviations) {
  ExternalTwinSettings settings = least_squares_twin();
  const ExternalCaseTwin one(settings);
  settings.workers = 3;
  const ExternalCaseTwin three(settings);
  EXPECT_LE(one.search_evaluations(), 4U * 64U + 2U * 32U);
  EXPECT_EQ(one.search_evaluations(), three.search_evaluations());
  // A Jacobian's d = 3 controls go in one request, each step's end in another.
  EXPECT_LT(one.search_requests(), one.search_evaluations());
  EXPECT_EQ(one.search_requests(), three.search_requests());
  for (const AssemblyId& x : one.assemblies()) {
    const double q0 = 0.04 + 0.01 * static_cast<double>((3 * x.upper + 5 * x.lower) % 7);
    EXPECT_NEAR(one.optimal_quality(x), std::sqrt(q0), 1e-9 * std::sqrt(q0))
        << fmt::format("{}", x);
    EXPECT_EQ(one.optimum(x), three.optimum(x));
  }
  EXPECT_EQ(one.key_point_count(), 4);
  MatrixX deviations(4, 1);
  one.deviations_batch({1, 2}, one.optimum({1, 2}), deviations);
  EXPECT_NEAR(deviations.norm() / 2.0, one.optimal_quality({1, 2}), 1e-12);
  // A scanned assembly alone: its rounds spread over the pool, to the same optimum.
  const nlohmann::json parts = {{"upper", nlohmann::json::array({0.25, 0.5})},
                                {"lower", nlohmann::json::array({1.5})}};
  ExternalCaseTwin pooled(settings);
  EXPECT_NEAR(pooled.optimal_quality(pooled.add_scanned(parts)), std::sqrt(0.04 + 0.01 * 2.75),
              1e-9);
  // The method needs the deviations; the settings say so, and round-trip through JSON.
  settings.key_points = 0;
  EXPECT_THAT(settings.validate().value_or(""),
              HasSubstr("optimum_method: value is least_squares; rule: least_squares needs a "
                        "program that answers its key points' deviations (key_points >= 1)"));
  settings.key_points = -2;
  EXPECT_THAT(settings.validate().value_or(""),
              HasSubstr("key_points: value is -2; rule: must lie in [0, 1000000]"));
  settings.key_points = 4;
  settings.optimum_seed = 99;
  const nlohmann::json json = settings;
  const auto read = json.get<ExternalTwinSettings>();
  EXPECT_EQ(read.key_points, 4);
  EXPECT_EQ(read.optimum_seed, 99U);
  nlohmann::json negative = json;
  negative["optimum_seed"] = -1;
  EXPECT_THROW((void)negative.get<ExternalTwinSettings>(), InvalidArgumentError);
}

// A config whose key_points is not the number of deviations the program answers is refused when
// the twin is made, naming the rule, rather than failing every model the controller fits later.
TEST(ExternalCaseTwin, RefusesKeyPointsTheProgramDoesNotAnswer) {
  ExternalTwinSettings settings = minimal_twin(1);
  settings.key_points = 5;  // the minimal twin answers 4
  try {
    const ExternalCaseTwin twin(settings);
    ADD_FAILURE() << "made a twin whose program answers 4 deviations with key_points 5";
  } catch (const std::exception& error) {
    EXPECT_THAT(error.what(), HasSubstr("has 4 deviations; rule: must have 5, one per key point "
                                        "(key_points)"));
  }
}

// A program that answers null for some controls (a solver that did not converge there) does not
// stop the search: such controls count as worse than any seen, and u0 is the best evaluated one.
TEST(ExternalCaseTwin, SearchStepsAroundControlsTheTwinCannotEvaluate) {
  ExternalTwinSettings settings = minimal_twin(2);
  settings.command = {"python3", TWINCAL_TEST_DATA_DIR "/holey_twin.py"};
  const ExternalCaseTwin twin(settings);
  for (const AssemblyId& x : twin.assemblies()) {
    const double q0 = 0.04 + 0.01 * static_cast<double>((3 * x.upper + 5 * x.lower) % 7);
    EXPECT_NEAR(twin.optimal_quality(x), std::sqrt(q0), 1e-6) << fmt::format("{}", x);
    EXPECT_LE(twin.optimum(x)(0), 0.5);
  }
}

// Twin ≠ plant for the external case: the plant is the same cell (locators, box, assemblies)
// measured by another program, e.g. the CalculiX contact solve behind its linear map.
TEST(ExternalTwinSettings, PlantExternalTwinIsTheSameCellMeasuredByAnotherProgram) {
  ExperimentConfig config;
  config.twin_case = TwinCase::external;
  config.external_twin = minimal_twin(1);
  config.plant_external_twin = minimal_twin(2);
  config.assemblies = 6;
  ASSERT_EQ(config.validate(), std::nullopt);
  const ExperimentConfig back = nlohmann::json(config).get<ExperimentConfig>();
  ASSERT_TRUE(back.plant_external_twin.has_value());
  EXPECT_EQ(back.plant_external_twin->workers, 2);
  // Its pool's size does not define the episodes; its program does.
  ExperimentConfig other = config;
  other.plant_external_twin->workers = 5;
  other.plant_external_twin->optima_file = "plant_optima.json";
  EXPECT_EQ(episode_defining_json(config), episode_defining_json(other));
  other.plant_external_twin->command.back() = "other_twin.py";
  EXPECT_NE(episode_defining_json(config), episode_defining_json(other));
  // The plant is built from it and answers for the same assemblies.
  const std::optional<AnyTwin> plant = make_plant(config);
  ASSERT_TRUE(plant.has_value());
  EXPECT_EQ(plant->locator_names(), (std::vector<std::string>{"A", "B", "C"}));
  // Another cell, or no external case, is refused with the rule.
  other = config;
  other.plant_external_twin->locators = {"A", "B", "D"};
  EXPECT_THAT(other.validate().value_or(""),
              HasSubstr("plant_external_twin: value is another cell than external_twin's"));
  other = config;
  other.plant_external_twin->upper_parts = 3;
  EXPECT_TRUE(other.validate().has_value());
  other = config;
  other.plant_external_twin->workers = 0;
  EXPECT_THAT(other.validate().value_or(""), HasSubstr("plant_external_twin.workers: value is 0"));
  ExperimentConfig body;
  body.plant_external_twin = minimal_twin(1);
  EXPECT_THAT(body.validate().value_or(""),
              HasSubstr("plant_external_twin: value is set; rule: only with the external case "
                        "(case is body): it is that case's plant"));
}

TEST(ExternalTwinSettings, RoundTripsThroughJsonAndRefusesUnknownKeys) {
  const ExternalTwinSettings settings = minimal_twin(4);
  const nlohmann::json json = settings;
  const auto back = json.get<ExternalTwinSettings>();
  EXPECT_EQ(nlohmann::json(back), json);
  ExternalTwinSettings read;
  from_json(nlohmann::json{{"command", "  python3  twin.py --fast "}}, read);
  EXPECT_EQ(read.command, (std::vector<std::string>{"python3", "twin.py", "--fast"}));
  try {
    from_json(nlohmann::json{{"comand", "x"}}, read);
    FAIL() << "an unknown key was accepted";
  } catch (const InvalidArgumentError& error) {
    EXPECT_THAT(error.what(), HasSubstr("key \"external_twin.comand\" is unknown"));
  }
  EXPECT_THROW(from_json(nlohmann::json{{"workers", "four"}}, read), InvalidArgumentError);
  // The start-up grace is a setting (a solver that loads a model before its first reply).
  from_json(nlohmann::json{{"startup_grace_ms", 60000}}, read);
  EXPECT_EQ(read.startup_grace_ms, 60000);
  EXPECT_EQ(nlohmann::json(read)["startup_grace_ms"], 60000);
  from_json(nlohmann::json{{"optima_file", "plant_optima.json"}}, read);
  EXPECT_EQ(read.optima_file, "plant_optima.json");
  EXPECT_EQ(nlohmann::json(read)["optima_file"], "plant_optima.json");
  ExternalTwinSettings impatient = minimal_twin(1);
  ASSERT_FALSE(impatient.validate().has_value());
  impatient.startup_grace_ms = -1;
  ASSERT_TRUE(impatient.validate().has_value());
  EXPECT_THAT(*impatient.validate(),
              HasSubstr("startup_grace_ms: value is -1; rule: must be >= 0"));
}

}  // namespace
}  // namespace twincal

namespace twincal {
namespace {

// A backend in this process: the minimal twin's formula, counting which worker served what.
class FormulaBackend final : public ExternalTwinBackend {
 public:
  explicit FormulaBackend(Index workers) : per_worker_(static_cast<std::size_t>(workers)) {}

  [[nodiscard]] Index workers() const override { return std::ssize(per_worker_); }
  [[nodiscard]] Index control_dimension() const override { return 3; }
  [[nodiscard]] const std::vector<std::string>& locator_names() const override { return names_; }
  [[nodiscard]] const VectorX& lower_bounds() const override { return lower_; }
  [[nodiscard]] const VectorX& upper_bounds() const override { return upper_; }
  [[nodiscard]] Index key_point_count() const override { return 0; }

  void quality_batch(const nlohmann::json& assembly, const Eigen::Ref<const MatrixX>& controls,
                     Eigen::Ref<VectorX> out) const override {
    batches_ += 1;
    if (controls.cols() > 1 &&
        std::ranges::count(failing_uppers_, assembly.at("upper").get<Index>()) > 0) {
      throw ExternalTwinError(ExternalTwinFailure::twin_error, assembly.dump(), controls,
                              "a transient failure, as the test asked");
    }
    if (evaluations_ != nullptr) *evaluations_ += controls.cols();
    evaluate(assembly, controls, out);
  }
  void deviations_batch(const nlohmann::json&, const Eigen::Ref<const MatrixX>&,
                        Eigen::Ref<MatrixX>) const override {
    require_key_points(key_point_count());
  }
  void worker_deviations_batch(Index, const nlohmann::json&, const Eigen::Ref<const MatrixX>&,
                               Eigen::Ref<MatrixX>) const override {
    require_key_points(key_point_count());
  }
  void worker_quality_batch(Index worker, const nlohmann::json& assembly,
                            const Eigen::Ref<const MatrixX>& controls,
                            Eigen::Ref<VectorX> out) const override {
    if ((answered_ += controls.cols()) > crash_after_) {
      throw ExternalTwinError(ExternalTwinFailure::crashed, assembly.dump(), controls,
                              "killed, as the test asked");
    }
    per_worker_.at(static_cast<std::size_t>(worker)) += controls.cols();
    if (evaluations_ != nullptr) *evaluations_ += controls.cols();
    evaluate(assembly, controls, out);
  }

  mutable std::vector<std::atomic<Index>> per_worker_;
  mutable std::atomic<Index> batches_{0};
  std::atomic<Index>* evaluations_ = nullptr;              // also counts every evaluation, when set
  Index crash_after_ = std::numeric_limits<Index>::max();  // evaluations a worker answers
  mutable std::atomic<Index> answered_{0};
  // The upper parts whose assemblies' batches of several controls (not the plant's, nor u0's
  // search in one control per request) fail, as a solver that does not converge on them.
  std::vector<Index> failing_uppers_;

 private:
  static void evaluate(const nlohmann::json& assembly, const Eigen::Ref<const MatrixX>& controls,
                       Eigen::Ref<VectorX> out) {
    const auto upper = static_cast<double>(assembly.at("upper").get<Index>());
    const auto lower = static_cast<double>(assembly.at("lower").get<Index>());
    for (Index j = 0; j < controls.cols(); ++j) {
      double sum = 0.04;
      for (Index i = 0; i < 3; ++i) {
        const double a = 0.2 * std::sin(1.7 * upper + 0.9 * lower + static_cast<double>(i));
        sum += (controls(i, j) - a) * (controls(i, j) - a);
      }
      out(j) = std::sqrt(sum);
    }
  }

  std::vector<std::string> names_{"A", "B", "C"};
  VectorX lower_ = VectorX::Constant(3, -1.0);
  VectorX upper_ = VectorX::Constant(3, 1.0);
};

TEST(ExternalCaseTwin, RunsOnTheBackendItsFactoryMakesAndSearchesOneAssemblyPerWorker) {
  ExternalTwinSettings settings = minimal_twin(1);
  settings.command = {"a-program-that-is-never-started"};
  const FormulaBackend* made = nullptr;
  const ExternalCaseTwin twin(settings, [&](const ExternalTwinSettings& given) {
    EXPECT_EQ(given.upper_parts, 2);
    auto backend = std::make_unique<FormulaBackend>(3);
    made = backend.get();
    return backend;
  });
  ASSERT_NE(made, nullptr);
  EXPECT_EQ(&twin.backend(), made);
  // The u0 searches went one request per worker at a time, spread over all three workers.
  Index searched = 0;
  for (const std::atomic<Index>& count : made->per_worker_) {
    EXPECT_GT(count.load(), 0);
    searched += count.load();
  }
  EXPECT_EQ(static_cast<std::uint64_t>(searched), twin.search_evaluations());
  EXPECT_NEAR(twin.optimal_quality({1, 2}), 0.2, 1e-9);
  // A batch goes to the backend as one batch.
  const MatrixX controls = MatrixX::Zero(3, 5);
  VectorX out(5);
  twin.quality_batch({1, 2}, controls, out);
  EXPECT_EQ(made->batches_.load(), 1);
  EXPECT_GT(out.minCoeff(), 0.2);
}

// A twin that fails now and then (on the five assemblies of upper part 1): each such assembly's
// model cannot be fitted, so it runs on the active controller's fallback, and its sigma-point
// update fails too, so its measurement is dropped; the episode goes on, counts both and keeps the
// first reason, and its trace marks them row by row (no longer silent, nor the end of the
// episode).
TEST(ExternalCaseTwin, AnEpisodeOfAFailingTwinGoesOnAndCountsItsFallbacksAndDroppedMeasurements) {
  std::vector<ExperimentGroup> groups(1);
  ExperimentGroup& group = groups.front();
  group.config.twin_case = TwinCase::external;
  group.config.external_twin = minimal_twin(1);
  group.config.external_twin->upper_parts = 4;
  group.config.external_twin->lower_parts = 5;
  group.config.assemblies = 20;
  FormulaBackend* made = nullptr;
  const std::vector<CaseTwin> twins = make_case_twins(groups, [&](const ExternalTwinSettings&) {
    auto backend = std::make_unique<FormulaBackend>(1);
    made = backend.get();
    return backend;
  });
  ASSERT_NE(made, nullptr);
  const EpisodeResult calm = run_episode(twins.front(), group.config, ControllerSpec::active(), 0);
  EXPECT_EQ(calm.fallbacks, 0);
  EXPECT_EQ(calm.dropped_measurements, 0);
  EXPECT_EQ(calm.first_fallback_at, -1);
  EXPECT_EQ(calm.first_fallback, "");

  made->failing_uppers_ = {1};
  std::ostringstream trace;
  const EpisodeResult result =
      write_episode_trace(twins.front(), group.config, ControllerSpec::active(), 0, trace);
  ASSERT_EQ(result.steps, 20);
  EXPECT_TRUE(result.failure.empty()) << result.failure;
  EXPECT_EQ(result.fallbacks, 5);
  EXPECT_EQ(result.dropped_measurements, 5);
  EXPECT_EQ(result.assemblies[static_cast<std::size_t>(result.first_fallback_at)].upper, 1);
  EXPECT_THAT(result.first_fallback, HasSubstr("a transient failure, as the test asked"));
  EXPECT_THAT(result.first_fallback, ::testing::StartsWith("proposal: "));
  // Columns 10 and 11 of every row (episode_trace_columns) say whether its assembly fell back
  // and whether its measurement was dropped.
  const auto columns = [](const std::string& line) {
    std::istringstream fields(line);
    std::vector<std::string> out(12);
    for (std::string& field : out) std::getline(fields, field, ',');
    return std::pair(out[10], out[11]);
  };
  std::istringstream lines(trace.str());
  std::string line;
  std::getline(lines, line);
  const std::pair<std::string, std::string> header("fell_back", "dropped_measurement");
  EXPECT_EQ(columns(line), header);
  Index fell_back = 0;
  Index dropped = 0;
  Index first = -1;
  for (Index t = 0; std::getline(lines, line); ++t) {
    const auto [proposal, measurement] = columns(line);
    fell_back += proposal == "true" ? 1 : 0;
    dropped += measurement == "true" ? 1 : 0;
    if (first < 0 && (proposal == "true" || measurement == "true")) first = t;
  }
  EXPECT_EQ(fell_back, result.fallbacks);
  EXPECT_EQ(dropped, result.dropped_measurements);
  EXPECT_EQ(first, result.first_fallback_at);
  // The baseline asks the twin nothing but u0: never a fallback.
  const EpisodeResult baseline =
      run_episode(twins.front(), group.config, ControllerSpec::baseline(), 0);
  EXPECT_EQ(baseline.fallbacks + baseline.dropped_measurements, 0);

  // A twin that fails at every batch: after twin_failure_streak assemblies in a row without it
  // the episode has lost its twin, a twin failure (not stored), not a result made without it.
  made->failing_uppers_ = {0, 1, 2, 3};
  try {
    (void)run_episode(twins.front(), group.config, ControllerSpec::active(), 0);
    ADD_FAILURE() << "an episode without its twin ended as a result";
  } catch (const TwinFailureError& error) {
    EXPECT_THAT(error.what(), HasSubstr("active run 0 step 4: the controller could not use its "
                                        "twin at 5 assemblies in a row (twin_failure_streak)"));
    EXPECT_THAT(error.what(), HasSubstr("a transient failure, as the test asked"));
  }
}

// A sweep over twins against one slow plant: groups that differ only in their twin share the
// plant a program of its own answers, so its assemblies' optima are searched once.
TEST(ExternalCaseTwin, GroupsOfOnePlantProgramShareIt) {
  std::vector<ExperimentGroup> groups(3);
  for (ExperimentGroup& group : groups) {
    group.config.twin_case = TwinCase::external;
    group.config.external_twin = minimal_twin(1);
    group.config.external_twin->command.emplace_back("--linear-map");
    group.config.plant_external_twin = minimal_twin(1);
    group.config.assemblies = 6;
  }
  groups[1].config.external_twin->command.back() = "--secant-map";
  groups[2].config.plant_external_twin->command.emplace_back("--another-plant");
  std::vector<std::vector<std::string>> made;
  const std::vector<CaseTwin> twins =
      make_case_twins(groups, [&](const ExternalTwinSettings& settings) {
        made.push_back(settings.command);
        return std::make_unique<FormulaBackend>(1);
      });
  ASSERT_EQ(twins.size(), 3U);
  // Two twins (groups 0 and 2 share theirs), two plants (groups 0 and 1 share theirs).
  EXPECT_EQ(made.size(), 4U);
  EXPECT_EQ(std::count(made.begin(), made.end(), groups[0].config.plant_external_twin->command), 1);
  EXPECT_EQ(&twins[0].full_twin().locator_names(), &twins[2].full_twin().locator_names());
  EXPECT_NE(&twins[0].full_twin().locator_names(), &twins[1].full_twin().locator_names());
}

// A slow program's search runs once per optima_file: the next twin of these settings reads it
// and asks its program nothing, with every bit of the optima the same.
TEST(ExternalCaseTwin, SearchesIntoItsOptimaFileOnceAndReadsItAfterwards) {
  ExternalTwinSettings settings = minimal_twin(2);
  settings.command = {"a-program-that-is-never-started"};
  settings.optima_file =
      (std::filesystem::path(::testing::TempDir()) / "twincal_case_twin_optima.json").string();
  std::filesystem::remove(settings.optima_file);
  std::atomic<Index> evaluations{0};
  const auto factory = [&](const ExternalTwinSettings& given) {
    auto backend = std::make_unique<FormulaBackend>(given.workers);
    backend->evaluations_ = &evaluations;
    return backend;
  };
  const ExternalCaseTwin searched(settings, factory);
  EXPECT_FALSE(searched.optima_read());
  EXPECT_GT(evaluations.load(), 6 * 300);
  ASSERT_TRUE(std::filesystem::exists(settings.optima_file));

  evaluations = 0;
  settings.workers = 1;  // changes no result, so the file serves it
  const ExternalCaseTwin read(settings, factory);
  EXPECT_TRUE(read.optima_read());
  EXPECT_EQ(evaluations.load(), 0);
  EXPECT_EQ(read.search_evaluations(), searched.search_evaluations());
  EXPECT_EQ(read.search_requests(), searched.search_requests());
  for (const AssemblyId& x : searched.assemblies()) {
    EXPECT_EQ(read.optimum(x), searched.optimum(x)) << fmt::format("{}", x);
    EXPECT_EQ(read.optimal_quality(x), searched.optimal_quality(x)) << fmt::format("{}", x);
  }

  settings.optimum_local_evaluations = 200;  // another search: refused, not searched over
  EXPECT_THROW(ExternalCaseTwin(settings, factory), InvalidArgumentError);
  EXPECT_EQ(evaluations.load(), 0);
}

// A study killed during the search keeps the pairs found so far: the next one searches only the
// others, and ends where an uninterrupted search does, to the bit and to the evaluation.
TEST(ExternalCaseTwin, ResumesAnInterruptedSearchFromItsOptimaFile) {
  for (const Index budget : {Index{0}, Index{14}}) {
    ExternalTwinSettings settings = minimal_twin(2);
    settings.command = {"a-program-that-is-never-started"};
    settings.optimum_budget = budget;
    const ExternalCaseTwin uninterrupted(
        settings, [](const ExternalTwinSettings&) { return std::make_unique<FormulaBackend>(2); });
    settings.optima_file =
        (std::filesystem::path(::testing::TempDir()) / "twincal_resumed_optima.json").string();
    std::filesystem::remove(settings.optima_file);
    std::atomic<Index> evaluations{0};
    Index crash_after = uninterrupted.search_evaluations() / 2;
    const auto factory = [&](const ExternalTwinSettings&) {
      auto backend = std::make_unique<FormulaBackend>(2);
      backend->evaluations_ = &evaluations;
      backend->crash_after_ = crash_after;
      return backend;
    };
    EXPECT_THROW(ExternalCaseTwin(settings, factory), ExternalTwinError);
    const std::optional<SearchedOptima> kept = read_searched_optima(settings.optima_file, settings);
    ASSERT_TRUE(kept.has_value());
    const auto found = std::count(kept->found.begin(), kept->found.end(), true);
    EXPECT_GT(found, 0) << "budget " << budget;
    EXPECT_LT(found, 6) << "budget " << budget;

    evaluations = 0;
    crash_after = std::numeric_limits<Index>::max();
    const ExternalCaseTwin resumed(settings, factory);
    EXPECT_FALSE(resumed.optima_read());
    EXPECT_LT(static_cast<std::uint64_t>(evaluations.load()), uninterrupted.search_evaluations());
    EXPECT_EQ(resumed.search_evaluations(), uninterrupted.search_evaluations());
    EXPECT_EQ(resumed.search_requests(), uninterrupted.search_requests());
    for (const AssemblyId& x : uninterrupted.assemblies()) {
      EXPECT_EQ(resumed.optimum(x), uninterrupted.optimum(x)) << fmt::format("{}", x);
      EXPECT_EQ(resumed.optimal_quality(x), uninterrupted.optimal_quality(x));
    }
    EXPECT_TRUE(read_searched_optima(settings.optima_file, settings)->complete());
  }
}

TEST(ExternalCaseTwin, RefusesAnOptimaFileItCannotWriteBeforeSearching) {
  ExternalTwinSettings settings = minimal_twin(1);
  settings.optima_file =
      (std::filesystem::path(::testing::TempDir()) / "twincal_no_such_folder" / "optima.json")
          .string();
  std::atomic<Index> evaluations{0};
  try {
    const ExternalCaseTwin twin(settings, [&](const ExternalTwinSettings&) {
      auto backend = std::make_unique<FormulaBackend>(1);
      backend->evaluations_ = &evaluations;
      return backend;
    });
    ADD_FAILURE() << "a twin with an optima_file in a missing folder was made";
  } catch (const InvalidArgumentError& error) {
    EXPECT_THAT(error.what(), HasSubstr("cannot be created"));
  }
  EXPECT_EQ(evaluations.load(), 0);
}

TEST(ExternalCaseTwin, RefusesAFactoryThatMakesNoBackend) {
  try {
    const ExternalCaseTwin twin(minimal_twin(1), [](const ExternalTwinSettings&) {
      return std::unique_ptr<ExternalTwinBackend>();
    });
    ADD_FAILURE() << "a twin without a backend was made";
  } catch (const InvalidArgumentError& error) {
    EXPECT_THAT(error.what(), HasSubstr("backend: the factory made none"));
  }
}

}  // namespace
}  // namespace twincal
