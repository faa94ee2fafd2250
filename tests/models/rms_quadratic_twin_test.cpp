#include "twincal/models/rms_quadratic_twin.hpp"

#include <set>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <Eigen/Eigenvalues>

#include "twincal/core/random_stream.hpp"

namespace twincal {
namespace {

RmsQuadraticTwinOptions options_with_dimension(Index d) {
  RmsQuadraticTwinOptions options;
  options.assemblies.dimension = d;
  return options;
}

TEST(AnalyticAssemblySet, HundredAssembliesFromTenUpperAndTenLowerParts) {
  const AnalyticAssemblySet set(AnalyticAssemblyOptions{}, RandomStream(1));
  EXPECT_EQ(set.size(), 100);
  const std::vector<AssemblyId> all = set.assemblies();
  ASSERT_EQ(all.size(), 100U);
  EXPECT_EQ(all.front(), (AssemblyId{0, 0}));
  EXPECT_EQ(all[1], (AssemblyId{0, 1}));
  EXPECT_EQ(all.back(), (AssemblyId{9, 9}));
  EXPECT_EQ(std::set<AssemblyId>(all.begin(), all.end()).size(), 100U);
  for (std::size_t k = 0; k < all.size(); ++k) {
    EXPECT_EQ(set.index_of(all[k]), static_cast<Index>(k));
  }
  EXPECT_THAT(set.locator_names(), ::testing::ElementsAre("u1", "u2", "u3"));
}

TEST(AnalyticAssemblySet, ParametersRespectTheirRangesAndComeFromTheParts) {
  AnalyticAssemblyOptions options;
  options.q0_min = 0.3;
  options.q0_max = 0.9;
  options.optimum_half_width = 0.15;
  const AnalyticAssemblySet set(options, RandomStream(2));
  for (const AssemblyId& x : set.assemblies()) {
    EXPECT_GE(set.q0(x), 0.3);
    EXPECT_LE(set.q0(x), 0.9);
    EXPECT_LE(set.optimum(x).cwiseAbs().maxCoeff(), 0.15);
  }
  // Additive parts: a(i, j) + a(k, l) = a(i, l) + a(k, j), and the same for q0.
  const AssemblyId ij{1, 2};
  const AssemblyId kl{7, 5};
  const AssemblyId il{1, 5};
  const AssemblyId kj{7, 2};
  EXPECT_NEAR(set.q0(ij) + set.q0(kl), set.q0(il) + set.q0(kj), 1e-15);
  EXPECT_TRUE(
      (set.optimum(ij) + set.optimum(kl)).isApprox(set.optimum(il) + set.optimum(kj), 1e-14));
  // Parts differ: not every assembly has the same optimum.
  EXPECT_NE(set.optimum(ij), set.optimum(kl));
}

TEST(AnalyticAssemblySet, RejectsInvalidOptionsAndUnknownAssemblies) {
  AnalyticAssemblyOptions bad;
  bad.optimum_half_width = 2.0;
  EXPECT_THAT([&] { (void)AnalyticAssemblySet(bad, RandomStream(1)); },
              ::testing::ThrowsMessage<InvalidArgumentError>(
                  "options: optimum_half_width and bound: values are 2 and 1; rule: 0 <= "
                  "optimum_half_width < bound < inf (every optimum is admissible)"));
  AnalyticAssemblyOptions names;
  names.locator_names = {"A", "B"};
  EXPECT_THAT([&] { (void)AnalyticAssemblySet(names, RandomStream(1)); },
              ::testing::ThrowsMessage<InvalidArgumentError>(
                  "options: locator_names: value is A, B; rule: must be empty or hold "
                  "dimension = 3 names"));
  const AnalyticAssemblySet set(AnalyticAssemblyOptions{}, RandomStream(1));
  EXPECT_THAT(
      [&] {
        (void)set.q0(AssemblyId{10, 0});
      },
      ::testing::ThrowsMessage<InvalidArgumentError>(
          "assembly.upper: value is 10; rule: must lie in [0, 9]"));
  EXPECT_THAT(
      [&] {
        (void)set.q0(AssemblyId{0, -1});
      },
      ::testing::ThrowsMessage<InvalidArgumentError>(
          "assembly.lower: value is -1; rule: must lie in [0, 9]"));
}

TEST(RmsQuadraticTwin, GenerationIsSeeded) {
  const RmsQuadraticTwin a = RmsQuadraticTwin::generate(options_with_dimension(4), RandomStream(7));
  const RmsQuadraticTwin b = RmsQuadraticTwin::generate(options_with_dimension(4), RandomStream(7));
  const RmsQuadraticTwin c = RmsQuadraticTwin::generate(options_with_dimension(4), RandomStream(8));
  EXPECT_EQ(a.curvature(), b.curvature());
  EXPECT_EQ(a.optimum({3, 4}), b.optimum({3, 4}));
  EXPECT_EQ(a.optimal_quality({3, 4}), b.optimal_quality({3, 4}));
  EXPECT_NE(a.curvature(), c.curvature());
  EXPECT_NE(a.optimum({3, 4}), c.optimum({3, 4}));
}

TEST(RmsQuadraticTwin, CurvatureIsSymmetricPositiveDefiniteWithinItsRange) {
  RmsQuadraticTwinOptions options = options_with_dimension(5);
  options.min_curvature = 0.2;
  options.max_curvature = 3.0;
  const RmsQuadraticTwin twin = RmsQuadraticTwin::generate(options, RandomStream(3));
  const MatrixX& h = twin.curvature();
  EXPECT_EQ(h, h.transpose());
  const Eigen::SelfAdjointEigenSolver<MatrixX> solver(h);
  EXPECT_GE(solver.eigenvalues().minCoeff(), 0.2 * (1.0 - 1e-12));
  EXPECT_LE(solver.eigenvalues().maxCoeff(), 3.0 * (1.0 + 1e-12));
  // The locators are coupled: H is not diagonal.
  EXPECT_GT((h - MatrixX(h.diagonal().asDiagonal())).cwiseAbs().maxCoeff(), 1e-3);
}

TEST(RmsQuadraticTwin, QualityIsTheRmsQuadraticWithExactOptimum) {
  const RmsQuadraticTwin twin =
      RmsQuadraticTwin::generate(options_with_dimension(3), RandomStream(4));
  RandomStream stream(9);
  for (const AssemblyId& x : twin.assemblies()) {
    const VectorX a = twin.optimum(x);
    const double z_star = twin.optimal_quality(x);
    EXPECT_EQ(twin.quality(x, a), z_star);
    EXPECT_EQ(z_star, std::sqrt(twin.assembly_set().q0(x)));
    VectorX u(3);
    stream.fill_normal(u);
    u *= 0.1;
    const VectorX e = u - a;
    const double expected = std::sqrt(twin.assembly_set().q0(x) + e.dot(twin.curvature() * e));
    EXPECT_NEAR(twin.quality(x, u), expected, 1e-15 * expected);
    EXPECT_GT(twin.quality(x, u), z_star);
  }
}

TEST(RmsQuadraticTwin, BatchMatchesSingleEvaluations) {
  const RmsQuadraticTwin twin =
      RmsQuadraticTwin::generate(options_with_dimension(3), RandomStream(4));
  MatrixX controls(3, 11);
  RandomStream(10).fill_normal(controls);
  VectorX out(11);
  twin.quality_batch({2, 8}, controls, out);
  for (Index j = 0; j < 11; ++j) EXPECT_EQ(out(j), twin.quality({2, 8}, controls.col(j)));
  // A fixed-size control binds to the twin's interface without conversion.
  const Eigen::Vector3d fixed = controls.col(0);
  EXPECT_EQ(twin.quality({2, 8}, fixed), out(0));
}

TEST(RmsQuadraticTwin, RejectsBadArguments) {
  const RmsQuadraticTwin twin =
      RmsQuadraticTwin::generate(options_with_dimension(3), RandomStream(4));
  EXPECT_THAT(
      [&] {
        (void)twin.quality({0, 0}, VectorX::Zero(2));
      },
      ::testing::ThrowsMessage<DimensionMismatchError>("control: size is 2; rule: must equal 3"));
  VectorX out(2);
  EXPECT_THAT(
      [&] {
        twin.quality_batch({0, 0}, MatrixX::Zero(3, 3), out);
      },
      ::testing::ThrowsMessage<DimensionMismatchError>("out: size is 2; rule: must equal 3"));
  RmsQuadraticTwinOptions bad = options_with_dimension(3);
  bad.min_curvature = 0.0;
  EXPECT_THAT([&] { (void)RmsQuadraticTwin::generate(bad, RandomStream(1)); },
              ::testing::ThrowsMessage<InvalidArgumentError>(
                  "options: min_curvature and max_curvature: values are 0 and 5; rule: 0 < "
                  "min_curvature <= max_curvature < inf"));
  const AnalyticAssemblySet set(AnalyticAssemblyOptions{}, RandomStream(1));
  EXPECT_THROW((void)RmsQuadraticTwin(set, MatrixX::Identity(2, 2)), DimensionMismatchError);
  EXPECT_THROW((void)RmsQuadraticTwin(set, -MatrixX::Identity(3, 3)), NotPositiveDefiniteError);
}

}  // namespace
}  // namespace twincal
