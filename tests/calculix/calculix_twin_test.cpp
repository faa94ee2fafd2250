#include "twincal/calculix/calculix_twin.hpp"

#include <sys/wait.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <utility>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "calculix_test_controls.hpp"
#include "twincal/external/external_twin_pool.hpp"
#include "twincal/sheet_metal/sheet_metal_twin.hpp"

// These tests run CalculiX (Debian: calculix-ccx, installed by scripts/install-dependencies.sh)
// on the 40 mm lap joint: a solve takes 0.05 s linear, 0.3–1 s with contact.

namespace twincal {
namespace {

using ::testing::HasSubstr;

CalculixOptions linear_options() {
  CalculixOptions options;
  options.contact = false;
  options.geometric_nonlinearity = false;
  return options;
}

CalculixOptions no_contact_options() {
  CalculixOptions options;
  options.contact = false;
  return options;
}

MatrixX box_controls(Index columns, std::uint64_t seed) {
  return test_support::random_controls(columns, seed, 0.8);
}

// Two independent FEMs of the same lap joint and parts: CalculiX's C3D8I solids and the
// project's ACM Kirchhoff plates (SheetMetalTwin), both linear. They discretize differently, so
// they agree as the meshes are refined, not on the coarse one: measured worst relative
// differences over these controls 6.2 % (40 mm), 2.6 % (20 mm), 0.54 % (10 mm); the ACM values
// hardly move, the solids' converge onto them.
TEST(CalculixTwin, LinearSolveConvergesOntoTheAcmTwin) {
  MatrixX controls(6, 4);
  controls << MatrixX::Zero(6, 1), box_controls(3, 11);
  double previous = 0.0;
  for (const Index refinement : {1, 2}) {
    CalculixOptions options = linear_options();
    options.refinement = refinement;
    const CalculixTwin calculix =
        CalculixTwin::generate(SheetMetalLayout::lap_joint(), options, 2023, 2, 2);
    SheetMetalLayout layout = SheetMetalLayout::lap_joint();
    layout.element_size /= static_cast<double>(refinement);
    SheetMetalTwinOptions acm_options;
    acm_options.upper_parts = 2;
    acm_options.lower_parts = 2;
    const SheetMetalTwin acm = SheetMetalTwin::generate(layout, acm_options, 2023);
    double worst = 0.0;
    for (const AssemblyId assembly : {AssemblyId{0, 0}, AssemblyId{1, 1}}) {
      VectorX q(controls.cols());
      calculix.quality_batch(assembly, controls, q);
      for (Index c = 0; c < controls.cols(); ++c) {
        const double reference = acm.quality(assembly, controls.col(c));
        worst = std::max(worst, std::abs(q(c) - reference) / reference);
      }
    }
    if (refinement == 1) {
      EXPECT_LT(worst, 0.08);
    } else {
      EXPECT_LT(worst, 0.03);
      EXPECT_LT(worst, 0.5 * previous);
    }
    previous = worst;
  }
}

// With large displacements on and no contact, small controls on flat parts give the linear
// solve: the geometric nonlinearity grows with the square of the displacements.
TEST(CalculixTwin, SmallDisplacementsMatchTheLinearSolve) {
  const std::vector<VectorX> flat{VectorX::Zero(66)};
  const CalculixTwin linear(SheetMetalLayout::lap_joint(), linear_options(), flat, flat);
  const CalculixTwin nonlinear(SheetMetalLayout::lap_joint(), no_contact_options(), flat, flat);
  const VectorX small = 0.005 * box_controls(1, 5).col(0);
  const double reference = linear.quality({0, 0}, small);
  EXPECT_NEAR(nonlinear.quality({0, 0}, small), reference, 2e-3 * reference);
  EXPECT_NEAR(linear.quality({0, 0}, 100.0 * small), 100.0 * reference, 1e-5 * reference);
}

// One deck for a batch: each column replaces every boundary condition, so a column's Q is its
// single solve's, up to the solver's tolerance and the results file's seven digits.
TEST(CalculixTwin, BatchEqualsSingleSolves) {
  const CalculixTwin twin =
      CalculixTwin::generate(SheetMetalLayout::lap_joint(), CalculixOptions{}, 2023, 1, 1);
  const MatrixX controls = box_controls(3, 7);
  VectorX batch(3);
  twin.quality_batch({0, 0}, controls, batch);
  for (Index c = 0; c < 3; ++c) {
    EXPECT_NEAR(batch(c), twin.quality({0, 0}, controls.col(c)), 1e-5 * batch(c)) << c;
  }
}

// The deviations of one deck are those Q is the RMS of (TwinWithDeviations).
TEST(CalculixTwin, AnswersTheDeviationsItsQualityIsTheRmsOf) {
  const CalculixTwin twin =
      CalculixTwin::generate(SheetMetalLayout::lap_joint(), linear_options(), 2023, 1, 1);
  const MatrixX controls = box_controls(2, 8);
  (void)test_support::expect_quality_is_rms_of_deviations(twin, {0, 0}, controls, 1e-9);
  MatrixX short_rows(twin.key_point_count() - 1, 2);
  EXPECT_THROW(twin.deviations_batch({0, 0}, controls, short_rows), DimensionMismatchError);
}

// Contact changes Q where the sheets press into each other; with a clearance no control can
// close, it is the contact-free solve.
TEST(CalculixTwin, ContactActsOnlyWhereGapsClose) {
  const auto make = [](CalculixOptions options) {
    return CalculixTwin::generate(SheetMetalLayout::lap_joint(), std::move(options), 2023, 1, 1);
  };
  CalculixOptions far_apart;
  far_apart.nominal_gap = 20.0;
  const CalculixTwin contact = make(CalculixOptions{});
  const CalculixTwin open = make(far_apart);
  const CalculixTwin none = make(no_contact_options());
  MatrixX controls(6, 2);
  controls << 0.0, -0.8, 0.0, -0.8, 0.0, -0.8, 0.0, 0.8, 0.0, 0.8, 0.0, 0.8;  // flanges pressed
  VectorX with(2);
  VectorX without(2);
  VectorX unreachable(2);
  contact.quality_batch({0, 0}, controls, with);
  none.quality_batch({0, 0}, controls, without);
  open.quality_batch({0, 0}, controls, unreachable);
  EXPECT_GT(std::abs(with(1) - without(1)), 0.01 * without(1));
  for (Index c = 0; c < 2; ++c) EXPECT_NEAR(unreachable(c), without(c), 1e-6 * without(c));
}

TEST(CalculixTwin, NonConvergenceIsNaNAndListed) {
  CalculixOptions options;
  options.max_increments = 2;  // the first weld step from the flat state needs about six
  const CalculixTwin twin =
      CalculixTwin::generate(SheetMetalLayout::lap_joint(), options, 2023, 1, 1);
  const MatrixX controls = box_controls(2, 3);
  VectorX q(2);
  const CalculixBatchSummary summary = twin.evaluate(twin.parts({0, 0}), controls, q, "test");
  EXPECT_TRUE(std::isnan(q(0)));
  EXPECT_TRUE(std::isnan(q(1)));
  EXPECT_EQ(summary.failed, (std::vector<Index>{0, 1}));
  EXPECT_EQ(summary.solver_runs, 2);  // each failed first in its deck: no retry alone
  EXPECT_THAT(summary.last_failure, HasSubstr("test, column 1 (u = ["));
  EXPECT_THAT(summary.last_failure, HasSubstr("max. # of increments"));
}

TEST(CalculixTwin, FailuresThatNoRetryMendsAreTypedErrors) {
  CalculixOptions missing = linear_options();
  missing.executable = "twincal-no-such-solver";
  const CalculixTwin absent =
      CalculixTwin::generate(SheetMetalLayout::lap_joint(), missing, 2023, 1, 1);
  try {
    (void)absent.quality({0, 0}, VectorX::Zero(6));
    FAIL() << "no error";
  } catch (const CalculixError& error) {
    EXPECT_EQ(error.failure(), CalculixFailure::missing_executable);
  }
  CalculixOptions hurried;
  hurried.timeout = std::chrono::milliseconds(1);
  const CalculixTwin slow =
      CalculixTwin::generate(SheetMetalLayout::lap_joint(), hurried, 2023, 1, 1);
  try {
    (void)slow.quality({0, 0}, VectorX::Zero(6));
    FAIL() << "no error";
  } catch (const CalculixError& error) {
    EXPECT_EQ(error.failure(), CalculixFailure::timeout);
  }
  const CalculixTwin twin =
      CalculixTwin::generate(SheetMetalLayout::lap_joint(), linear_options(), 2023, 2, 3);
  EXPECT_THROW((void)twin.quality({2, 0}, VectorX::Zero(6)), InvalidArgumentError);
  EXPECT_THROW((void)twin.quality({0, 0}, VectorX::Zero(5)), DimensionMismatchError);
}

TEST(CalculixTwin, ScratchDirectoriesAreRemovedUnlessKept) {
  const std::filesystem::path root =
      std::filesystem::temp_directory_path() / "twincal-calculix-twin-test";
  std::filesystem::remove_all(root);
  CalculixOptions options = linear_options();
  options.scratch_root = root;
  const CalculixTwin twin =
      CalculixTwin::generate(SheetMetalLayout::lap_joint(), options, 2023, 1, 1);
  (void)twin.quality({0, 0}, VectorX::Zero(6));
  EXPECT_TRUE(std::filesystem::is_empty(root));
  options.keep_files = true;
  const CalculixTwin keeping =
      CalculixTwin::generate(SheetMetalLayout::lap_joint(), options, 2023, 1, 1);
  (void)keeping.quality({0, 0}, VectorX::Zero(6));
  const std::filesystem::directory_iterator kept(root);
  ASSERT_NE(kept, std::filesystem::directory_iterator{});
  EXPECT_TRUE(std::filesystem::exists(kept->path() / "columns-0-0.inp"));
  EXPECT_TRUE(std::filesystem::exists(kept->path() / "columns-0-0.dat"));
  std::filesystem::remove_all(root);
}

// The program speaks the external-twin protocol: through a pool of two workers it answers what
// the twin in this process computes, bit for bit (the same decks, the same results files).
TEST(CalculixTwinProgram, ServesTheTwinThroughThePool) {
  ExternalTwinPoolOptions options;
  options.twin.command = {TWINCAL_CALCULIX_TWIN_PROGRAM,
                          "--layout",
                          "lap-joint",
                          "--linear",
                          "--upper-parts",
                          "2",
                          "--lower-parts",
                          "2"};
  options.twin.locator_names = {"U1", "U2", "U3", "L1", "L2", "L3"};
  options.twin.lower_bounds = VectorX::Constant(6, -1.0);
  options.twin.upper_bounds = VectorX::Constant(6, 1.0);
  options.twin.timeout = std::chrono::milliseconds(60000);
  options.workers = 2;
  const CalculixTwin twin =
      CalculixTwin::generate(SheetMetalLayout::lap_joint(), linear_options(), 2023, 2, 2);
  options.twin.key_points = twin.key_point_count();
  const ExternalTwinPool pool(options);
  const MatrixX controls = box_controls(3, 9);
  VectorX served(3);
  VectorX here(3);
  pool.quality_batch(nlohmann::json{{"upper", 1}, {"lower", 0}}, controls, served);
  twin.quality_batch({1, 0}, controls, here);
  EXPECT_EQ(served, here);
  // A scanned assembly: the parts themselves.
  const CalculixParts parts = twin.parts({1, 0});
  nlohmann::json scanned = {
      {"parts",
       {{"upper", std::vector<double>(parts.upper.begin(), parts.upper.end())},
        {"lower", std::vector<double>(parts.lower.begin(), parts.lower.end())}}}};
  VectorX from_scan(3);
  pool.quality_batch(scanned, controls, from_scan);
  EXPECT_EQ(from_scan, here);
  // The key points' deviations ("deviations": true), of a listed and of a scanned assembly.
  MatrixX deviations_served(twin.key_point_count(), 3);
  MatrixX deviations_here(twin.key_point_count(), 3);
  pool.deviations_batch(nlohmann::json{{"upper", 1}, {"lower", 0}}, controls, deviations_served);
  twin.deviations_batch({1, 0}, controls, deviations_here);
  EXPECT_EQ(deviations_served, deviations_here);
  pool.deviations_batch(scanned, controls, deviations_served);
  EXPECT_EQ(deviations_served, deviations_here);
  // A request it refuses names the rule.
  scanned["parts"]["upper"] = std::vector<double>(3, 0.0);
  try {
    pool.quality_batch(scanned, controls, from_scan);
    FAIL() << "accepted parts of the wrong size";
  } catch (const ExternalTwinError& error) {
    EXPECT_THAT(error.what(), HasSubstr("assembly.parts.upper: 3 values"));
  }
}

// The program's own arguments: the influence map's options are refused with their rule where
// they would do nothing or are out of range, before anything is solved (exit status 2).
TEST(CalculixTwinProgram, RefusesInfluenceOptionsItCannotHonour) {
  const auto run = [](const std::string& arguments) {
    const std::string command =
        std::string(TWINCAL_CALCULIX_TWIN_PROGRAM) + " " + arguments + " 2>&1 </dev/null";
    FILE* pipe = popen(command.c_str(), "r");
    std::string output;
    if (pipe == nullptr) return std::pair{-1, output};
    char buffer[256];
    while (std::fgets(buffer, sizeof buffer, pipe) != nullptr) output += buffer;
    const int status = pclose(pipe);
    return std::pair{WIFEXITED(status) ? WEXITSTATUS(status) : -1, output};
  };
  const auto [alone, alone_output] = run("--layout lap-joint --linearization secant");
  EXPECT_EQ(alone, 2);
  EXPECT_THAT(alone_output, HasSubstr("given without --influence"));
  const auto [unknown, unknown_output] = run("--influence --linearization tangent");
  EXPECT_EQ(unknown, 2);
  EXPECT_THAT(unknown_output,
              HasSubstr("--linearization: value is 'tangent'; rule: small-displacement or secant"));
  const auto [wide, wide_output] = run("--influence --secant-step-fraction 0.7");
  EXPECT_EQ(wide, 2);
  EXPECT_THAT(wide_output,
              HasSubstr("secant_step_fraction: value is 0.7; rule: must lie in (0, 0.5]"));
}

}  // namespace
}  // namespace twincal
