#include "twincal/calculix/influence_coefficient_twin.hpp"

#include <cmath>

#include <gtest/gtest.h>

#include "calculix_test_controls.hpp"

namespace twincal {
namespace {

CalculixTwin lap_joint(bool linear) {
  CalculixOptions options;
  options.contact = !linear && options.contact;
  options.geometric_nonlinearity = !linear;
  return CalculixTwin::generate(SheetMetalLayout::lap_joint(), options, 2023, 2, 3);
}

MatrixX random_controls(Index columns, std::uint64_t seed) {
  return test_support::random_controls(columns, seed, 1.0);
}

// The parts' scaled copy: the same shapes, `factor` times the deviation.
CalculixTwin scaled(const CalculixTwin& twin, double factor, bool linear) {
  std::vector<VectorX> upper;
  std::vector<VectorX> lower;
  for (Index i = 0; i < twin.upper_part_count(); ++i)
    upper.push_back(factor * twin.parts({i, 0}).upper);
  for (Index j = 0; j < twin.lower_part_count(); ++j)
    lower.push_back(factor * twin.parts({0, j}).lower);
  CalculixOptions options;
  options.contact = !linear;
  options.geometric_nonlinearity = !linear;
  return {SheetMetalLayout::lap_joint(), options, upper, lower};
}

double worst_difference(const InfluenceCoefficientTwin& influence, const CalculixTwin& linear,
                        const MatrixX& controls) {
  double worst = 0.0;
  for (const AssemblyId assembly : {AssemblyId{0, 0}, AssemblyId{1, 2}}) {
    VectorX direct(controls.cols());
    VectorX mapped(controls.cols());
    linear.quality_batch(assembly, controls, direct);
    influence.quality_batch(assembly, controls, mapped);
    worst = std::max(worst, ((mapped - direct).array().abs() / direct.array()).maxCoeff());
  }
  return worst;
}

// On flat parts the linear solve is exactly linear in u: the map reproduces it to the results
// file's seven digits. The map is built from the contact twin: it solves linear regardless.
TEST(InfluenceCoefficientTwin, ReproducesTheLinearSolveOnNominalGeometry) {
  const CalculixTwin flat = scaled(lap_joint(false), 0.0, false);
  const InfluenceCoefficientTwin influence(flat);
  EXPECT_EQ(influence.solver_runs(), 1 + 2 + 3);
  EXPECT_EQ(influence.influence().rows(), 8);
  EXPECT_EQ(influence.influence().cols(), 6);
  EXPECT_LT(worst_difference(influence, scaled(flat, 1.0, true), random_controls(4, 3)), 1e-5);
}

// With deviated parts the CalculiX model's geometry is the deviated shape, and its stiffness
// depends on it; the map, like every MIC model, keeps the nominal (flat) stiffness. The
// difference is that linearization's error: measured 0.75 % at the parts' full deviation
// (σ = 0.25 mm on 0.8 mm sheets), and it shrinks with the deviation.
TEST(InfluenceCoefficientTwin, DeviatedGeometryIsALinearizationError) {
  const CalculixTwin full = lap_joint(true);
  const MatrixX controls = random_controls(4, 3);
  const double at_full = worst_difference(InfluenceCoefficientTwin(full), full, controls);
  const CalculixTwin tenth = scaled(full, 0.1, true);
  const double at_tenth = worst_difference(InfluenceCoefficientTwin(tenth), tenth, controls);
  EXPECT_LT(at_full, 0.02);
  EXPECT_LT(at_tenth, 0.2 * at_full);
  // Scanned parts: y0 from one solve of both parts equals the sum of the two single-part
  // solves up to the same linearization error.
  const InfluenceCoefficientTwin influence(full);
  VectorX mapped(4);
  VectorX scanned(4);
  influence.quality_batch(AssemblyId{1, 2}, controls, mapped);
  influence.quality_batch(full.parts({1, 2}), controls, scanned);
  EXPECT_LT(((scanned - mapped).array().abs() / mapped.array()).maxCoeff(), 0.02);
}

TEST(InfluenceCoefficientTwin, OptimumIsTheBoxMinimum) {
  const InfluenceCoefficientTwin influence(lap_joint(true));
  const MatrixX controls = random_controls(200, 5);
  for (const AssemblyId assembly : {AssemblyId{0, 1}, AssemblyId{1, 0}}) {
    const VectorX u0 = influence.optimum(assembly);
    EXPECT_TRUE((u0.array() >= -1.0 - 1e-12).all() && (u0.array() <= 1.0 + 1e-12).all());
    const double best = influence.optimal_quality(assembly);
    VectorX q(200);
    influence.quality_batch(assembly, controls, q);
    EXPECT_LE(best, q.minCoeff());
    EXPECT_LT(best, influence.quality(assembly, VectorX::Zero(6)));
  }
  EXPECT_THROW((void)influence.quality({2, 0}, VectorX::Zero(6)), InvalidArgumentError);
  EXPECT_THROW((void)influence.quality({0, 0}, VectorX::Zero(4)), DimensionMismatchError);
}

// The map's deviations are what its Q is the RMS of, a batch gives each control's to the bit, and
// a wrong shape is refused (models' DeviationsConformance, which needs no solver, says the same
// of the FEM twins).
TEST(InfluenceCoefficientTwin, AnswersTheDeviationsItsQualityIsTheRmsOf) {
  const InfluenceCoefficientTwin influence(lap_joint(true));
  const Index m = influence.key_point_count();
  const MatrixX controls = random_controls(5, 6);
  MatrixX deviations =
      test_support::expect_quality_is_rms_of_deviations(influence, {1, 2}, controls, 1e-12);
  for (Index k = 0; k < 5; ++k) {
    MatrixX alone(m, 1);
    influence.deviations_batch({1, 2}, controls.col(k), alone);
    EXPECT_EQ(alone.col(0), deviations.col(k)) << k;
  }
  MatrixX short_rows(m - 1, 5);
  EXPECT_THROW(influence.deviations_batch({1, 2}, controls, short_rows), DimensionMismatchError);
  EXPECT_THROW(influence.deviations_batch({2, 0}, controls, deviations), InvalidArgumentError);
  // Scanned parts: one solve for their y0, then the same B; Q is their RMS too.
  const CalculixParts parts = lap_joint(true).parts({1, 2});
  MatrixX scanned(m, 5);
  influence.deviations_batch(parts, controls, scanned);
  VectorX scanned_quality(5);
  influence.quality_batch(parts, controls, scanned_quality);
  EXPECT_TRUE((scanned.colwise().norm().transpose() / std::sqrt(static_cast<double>(m)))
                  .isApprox(scanned_quality, 1e-12));
  EXPECT_THROW(influence.deviations_batch(parts, controls, short_rows), DimensionMismatchError);
}

InfluenceCoefficientOptions secant_options() {
  InfluenceCoefficientOptions options;
  options.linearization = InfluenceLinearization::secant;
  return options;
}

TEST(InfluenceCoefficientOptions, EachRuleNamesItsFieldAndValue) {
  EXPECT_FALSE(InfluenceCoefficientOptions{}.validate());
  EXPECT_FALSE(secant_options().validate());
  for (const double fraction : {0.0, -0.1, 0.51, std::nan("")}) {
    InfluenceCoefficientOptions options = secant_options();
    options.secant_step_fraction = fraction;
    const std::optional<std::string> problem = options.validate();
    ASSERT_TRUE(problem) << fraction;
    EXPECT_NE(problem->find("secant_step_fraction: value is"), std::string::npos) << *problem;
    EXPECT_NE(problem->find("must lie in (0, 0.5]"), std::string::npos) << *problem;
  }
  for (const InfluenceLinearization linearization :
       {InfluenceLinearization::small_displacement, InfluenceLinearization::secant}) {
    EXPECT_EQ(parse_influence_linearization(to_string(linearization)), linearization);
  }
  EXPECT_FALSE(parse_influence_linearization("tangent"));
}

// Options are checked before anything is solved: a twin whose solver does not exist gets the
// options' error, not the solver's.
TEST(InfluenceCoefficientTwin, RefusesInvalidOptionsBeforeSolving) {
  CalculixOptions solver;
  solver.executable = "/nonexistent/ccx";
  const CalculixTwin twin =
      CalculixTwin::generate(SheetMetalLayout::lap_joint(), solver, 2023, 1, 1);
  InfluenceCoefficientOptions options = secant_options();
  options.secant_step_fraction = 0.75;
  EXPECT_THROW(InfluenceCoefficientTwin(twin, options), InvalidArgumentError);
  EXPECT_THROW(InfluenceCoefficientTwin(twin, secant_options()), CalculixError);
}

// On the linear solve the secants are the unit displacements' responses (the solve is affine in
// u) and the parts' responses at the centre (0) are the small-displacement map's: both maps agree
// to the results file's digits, which checks how the secant map composes y_U, y_L and B c.
TEST(InfluenceCoefficientTwin, SecantOfTheLinearSolveIsTheLinearMap) {
  const CalculixTwin linear = lap_joint(true);
  const InfluenceCoefficientTwin small(linear);
  const InfluenceCoefficientTwin secant(linear, secant_options());
  EXPECT_EQ(secant.options().linearization, InfluenceLinearization::secant);
  EXPECT_EQ(secant.solver_runs(), 1 + 2 + 3);  // one deck of 2d + 1 controls, one per part
  EXPECT_LT((secant.influence() - small.influence()).cwiseAbs().maxCoeff(),
            1e-5 * small.influence().cwiseAbs().maxCoeff());
  for (const AssemblyId assembly : {AssemblyId{0, 0}, AssemblyId{1, 2}}) {
    EXPECT_LT((secant.unadjusted_deviations(assembly) - small.unadjusted_deviations(assembly))
                  .cwiseAbs()
                  .maxCoeff(),
              1e-5 * small.unadjusted_deviations(assembly).cwiseAbs().maxCoeff())
        << assembly.upper << ", " << assembly.lower;
  }
}

// Behind the contact solve with large displacements the small-displacement map misjudges the
// membrane stiffening of half-millimetre adjustments; the secants across that range follow the
// solve closely. The worst relative error in Q against the contact solve itself over four
// controls within ±½ mm at two assemblies, measured 2026-11-30 (CalculiX 2.20): 205 % for the
// small-displacement map, 9.4 % for the secants.
TEST(InfluenceCoefficientTwin, SecantFollowsTheContactSolveWhereTheLinearMapDoesNot) {
  const CalculixTwin contact = lap_joint(false);
  const MatrixX controls = test_support::random_controls(4, 11, 0.5);
  const double small = worst_difference(InfluenceCoefficientTwin(contact), contact, controls);
  const InfluenceCoefficientTwin secant(contact, secant_options());
  const double secant_error = worst_difference(secant, contact, controls);
  EXPECT_LT(secant_error, 0.15);
  EXPECT_LT(secant_error, 0.25 * small);
  // Scanned parts: one contact solve at the centre c gives their y0, so there the map is the
  // solve itself.
  const VectorX centre = VectorX::Zero(6);
  VectorX at_centre(1);
  secant.quality_batch(contact.parts({1, 2}), centre, at_centre);
  EXPECT_NEAR(at_centre(0), contact.quality({1, 2}, centre), 1e-12 * at_centre(0));
}

}  // namespace
}  // namespace twincal
