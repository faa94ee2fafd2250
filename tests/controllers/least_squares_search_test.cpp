#include "twincal/controllers/least_squares_search.hpp"

#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "affine_key_points.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/models/contact_nonlinearity.hpp"
#include "twincal/models/key_point_twin.hpp"

namespace twincal::least_squares_search_test {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

using search_test_support::AffineKeyPoints;
using search_test_support::total;

// r(u) = a + B u as the twin's deviations.
struct Affine : AffineKeyPoints {
  Affine(Index m, Index d, std::uint64_t seed)
      : AffineKeyPoints(m, d, seed, "least squares test") {}
  // Evaluates each column, checking it lies in [lower, upper]; records the batch sizes.
  [[nodiscard]] DeviationObjective objective(const VectorX& lower, const VectorX& upper,
                                             std::vector<Index>& batch_sizes) const {
    return [this, lower, upper, &batch_sizes](const Eigen::Ref<const MatrixX>& points,
                                              Eigen::Ref<MatrixX> deviations) {
      EXPECT_EQ(deviations.rows(), a.size());
      EXPECT_EQ(deviations.cols(), points.cols());
      check_batch(points, lower, upper, batch_sizes);
      for (Index k = 0; k < points.cols(); ++k) deviations.col(k) = a + b * points.col(k);
    };
  }
  // A search from 0 over [−half_width, half_width]^d, restarts from RandomStream(seed); the
  // sizes of the batches it asked for into `batches`.
  [[nodiscard]] LeastSquaresSearchResult search(const LeastSquaresSearchOptions& options,
                                                double half_width, std::uint64_t seed,
                                                std::vector<Index>& batches) const {
    const VectorX upper = VectorX::Constant(b.cols(), half_width);
    const VectorX lower = -upper;
    return LeastSquaresSearch(options).minimize(objective(lower, upper, batches), a.size(),
                                                VectorX::Zero(b.cols()), lower, upper,
                                                RandomStream(seed));
  }
};

TEST(LeastSquaresSearch, FindsTheMinimumOfAffineDeviationsInOneLocalSearch) {
  const Index d = 5;
  const Affine problem(30, d, 1);
  std::vector<Index> batches;
  const LeastSquaresSearchResult result =
      problem.search({.evaluations = 200, .restart_spread = 0.0}, 10.0, 2, batches);
  EXPECT_LT((result.argmin - problem.argmin()).norm(), 1e-7) << result.summary();
  EXPECT_NEAR(result.minimum, problem.quality(problem.argmin()), 1e-12);
  EXPECT_EQ(result.status, LeastSquaresStatus::converged);
  EXPECT_EQ(result.local_searches, 1);
  EXPECT_EQ(static_cast<Index>(batches.size()), result.batches);
  EXPECT_EQ(static_cast<std::uint64_t>(total(batches)), result.evaluations);
  // Affine deviations: the forward differences are the Jacobian, so a few Gauss–Newton steps.
  EXPECT_LE(result.jacobians, 6) << result.summary();
}

TEST(LeastSquaresSearch, AsksForEachJacobianInOneBatchAndEachStepAlone) {
  const Index d = 4;
  const Affine problem(20, d, 3);
  std::vector<Index> batches;
  const LeastSquaresSearchResult result = problem.search({.evaluations = 60}, 5.0, 4, batches);
  Index jacobians = 0;
  for (const Index size : batches) {
    EXPECT_TRUE(size == 1 || size == d) << "a batch of " << size;
    jacobians += size == d ? 1 : 0;
  }
  EXPECT_EQ(jacobians, result.jacobians);
}

TEST(LeastSquaresSearch, NeverSpendsMoreThanItsBudget) {
  const Index d = 3;
  const Affine problem(12, d, 5);
  for (const bool speculative : {false, true}) {
    for (const std::uint64_t budget : {1U, 2U, 4U, 5U, 6U, 9U, 17U, 50U}) {
      std::vector<Index> batches;
      const LeastSquaresSearchResult result = problem.search(
          {.evaluations = budget, .speculative_jacobian = speculative}, 1.0, 6, batches);
      SCOPED_TRACE(::testing::Message() << "budget " << budget << ", speculative " << speculative
                                        << ": " << result.summary());
      EXPECT_LE(static_cast<std::uint64_t>(total(batches)), budget);
      EXPECT_EQ(static_cast<std::uint64_t>(total(batches)), result.evaluations);
      EXPECT_LE(result.minimum, problem.quality(VectorX::Zero(d)));
      if (budget >= 5) {  // a start, a Jacobian and a step: restarts spend the rest
        EXPECT_GE(result.evaluations + d + 1, budget);
      }
    }
  }
}

// speculative_jacobian: a start and each trial step come with the Jacobian's stencil at their
// point in one request, so the search asks for the same minimum in fewer requests.
TEST(LeastSquaresSearch, ASpeculativeJacobianComesWithItsPointInOneRequest) {
  const Index d = 5;
  const Affine problem(30, d, 1);
  const double half_width = 10.0;
  const double step = 0.01 * 2.0 * half_width;  // difference_step of the box's width
  std::vector<Index> sizes;
  Index stencils = 0;
  const VectorX upper = VectorX::Constant(d, half_width);
  const VectorX lower = -upper;
  const DeviationObjective affine = problem.objective(lower, upper, sizes);
  const DeviationObjective objective = [&](const Eigen::Ref<const MatrixX>& points,
                                           Eigen::Ref<MatrixX> deviations) {
    if (points.cols() == d + 1) {  // the point, then its forward differences towards the inside
      ++stencils;
      for (Index i = 0; i < d; ++i) {
        VectorX moved = points.col(i + 1) - points.col(0);
        EXPECT_NEAR(std::abs(moved(i)), step, 1e-12) << "locator " << i;
        moved(i) = 0.0;
        EXPECT_EQ(moved.norm(), 0.0) << "locator " << i;
      }
    }
    affine(points, deviations);
  };
  const LeastSquaresSearchOptions options{
      .evaluations = 200, .restart_spread = 0.0, .speculative_jacobian = true};
  const LeastSquaresSearchResult result = LeastSquaresSearch(options).minimize(
      objective, 30, VectorX::Zero(d), lower, upper, RandomStream(2));
  EXPECT_LT((result.argmin - problem.argmin()).norm(), 1e-7) << result.summary();
  EXPECT_EQ(result.status, LeastSquaresStatus::converged);
  EXPECT_EQ(static_cast<Index>(sizes.size()), result.batches);
  EXPECT_EQ(static_cast<std::uint64_t>(total(sizes)), result.evaluations);
  EXPECT_EQ(stencils, result.batches) << "every request a point with its stencil";
  EXPECT_GE(stencils, result.jacobians);

  std::vector<Index> plain_sizes;
  const LeastSquaresSearchResult plain =
      problem.search({.evaluations = 200, .restart_spread = 0.0}, half_width, 2, plain_sizes);
  EXPECT_LT(result.batches, plain.batches) << result.summary() << "; " << plain.summary();
  EXPECT_NEAR(result.minimum, plain.minimum, 1e-12);
}

TEST(LeastSquaresSearch, StopsAtTheBoxWhereTheMinimumLiesOutsideIt) {
  const Index d = 3;
  const Affine problem(15, d, 7);
  const VectorX free = problem.argmin();
  // The box ends halfway to the free minimum on locator 0.
  VectorX lower = free.array() - 1.0;
  VectorX upper = free.array() + 1.0;
  upper(0) = 0.5 * free(0) + 0.5 * lower(0);
  std::vector<Index> batches;
  const VectorX start = 0.5 * (lower + upper);
  const LeastSquaresSearchResult result = LeastSquaresSearch({.evaluations = 200})
                                              .minimize(problem.objective(lower, upper, batches),
                                                        15, start, lower, upper, RandomStream(8));
  EXPECT_NEAR(result.argmin(0), upper(0), 1e-9) << result.summary();
  // The best point on that face: ‖r‖² restricted to u0 = upper(0) is a quadratic in the rest.
  const MatrixX rest = problem.b.rightCols(d - 1);
  const VectorX fixed = problem.a + problem.b.col(0) * upper(0);
  VectorX face(d);
  face(0) = upper(0);
  face.tail(d - 1) = rest.colPivHouseholderQr().solve(-fixed);
  ASSERT_TRUE(((face.array() >= lower.array()) && (face.array() <= upper.array())).all());
  EXPECT_NEAR(result.minimum, problem.quality(face), 1e-9);
}

// A 2-locator key-point twin with contact: the search reaches the minimum a fine grid finds
// (‖r‖ is piecewise affine with kinks where contacts close, and has several basins: with 100
// evaluations 3 of these 30 assemblies ended in a worse basin, 6 of 30 for the trust region).
TEST(LeastSquaresSearch, ReachesTheGridMinimumOfATwinWithContact) {
  KeyPointTwinOptions options;
  options.assemblies.dimension = 2;
  options.key_points = 24;
  const KeyPointTwin<ContactNonlinearity> twin(options, RandomStream(9));
  const VectorX& lower = twin.lower_bounds();
  const VectorX& upper = twin.upper_bounds();
  const Index n = 201;
  MatrixX grid(2, n * n);
  for (Index i = 0; i < n; ++i) {
    for (Index j = 0; j < n; ++j) {
      grid(0, i * n + j) = lower(0) + (upper(0) - lower(0)) * static_cast<double>(i) / (n - 1);
      grid(1, i * n + j) = lower(1) + (upper(1) - lower(1)) * static_cast<double>(j) / (n - 1);
    }
  }
  const LeastSquaresSearch search({.evaluations = 200});
  const RandomStream restarts(10);
  Index contacts_met = 0;
  for (const AssemblyId& assembly : twin.assemblies()) {
    if (assembly.upper > 2) continue;
    VectorX on_grid(grid.cols());
    twin.quality_batch(assembly, grid, on_grid);
    const DeviationObjective objective = [&](const Eigen::Ref<const MatrixX>& controls,
                                             Eigen::Ref<MatrixX> deviations) {
      twin.deviations_batch(assembly, controls, deviations);
    };
    const VectorX start = twin.search_start(assembly);
    const LeastSquaresSearchResult result =
        search.minimize(objective, twin.key_point_count(), start, lower, upper,
                        restarts.substream(static_cast<std::uint64_t>(assembly.lower)));
    EXPECT_LE(result.minimum, on_grid.minCoeff() * (1.0 + 1e-6))
        << "assembly (" << assembly.upper << ", " << assembly.lower << "): " << result.summary()
        << ", grid " << on_grid.minCoeff();
    EXPECT_NEAR(result.minimum, twin.quality(assembly, result.argmin), 1e-12);
    // The affine optimum is not the twin's where a contact closes there or nearby.
    contacts_met += on_grid.minCoeff() < twin.quality(assembly, start) - 1e-6 ? 1 : 0;
  }
  EXPECT_GT(contacts_met, 0) << "no assembly's contact moved its optimum: the test sees no kink";
}

TEST(LeastSquaresSearch, StopsOnceRestartsKeepReturningToTheBestMinimum) {
  const Index d = 4;
  const Affine problem(20, d, 15);
  std::vector<Index> batches;
  const LeastSquaresSearchResult result =
      problem.search({.evaluations = 1000, .agreeing_restarts = 3}, 5.0, 16, batches);
  // One basin: the first local search and three restarts that all come back to it.
  EXPECT_EQ(result.local_searches, 4) << result.summary();
  EXPECT_EQ(result.status, LeastSquaresStatus::converged);
  EXPECT_LT(result.evaluations, 1000U);
  EXPECT_LT((result.argmin - problem.argmin()).norm(), 1e-7);
  // Without the rule the restarts spend the budget.
  const LeastSquaresSearchResult spent = problem.search({.evaluations = 1000}, 5.0, 16, batches);
  EXPECT_GE(spent.evaluations + d + 1, 1000U) << spent.summary();
}

TEST(LeastSquaresSearch, RestartsAreReproducibleFromTheirStream) {
  KeyPointTwinOptions options;
  options.assemblies.dimension = 3;
  const KeyPointTwin<ContactNonlinearity> twin(options, RandomStream(11));
  const AssemblyId assembly{1, 2};
  const DeviationObjective objective = [&](const Eigen::Ref<const MatrixX>& controls,
                                           Eigen::Ref<MatrixX> deviations) {
    twin.deviations_batch(assembly, controls, deviations);
  };
  const LeastSquaresSearch search({.evaluations = 64});
  const auto run = [&](std::uint64_t seed) {
    return search.minimize(objective, twin.key_point_count(), twin.search_start(assembly),
                           twin.lower_bounds(), twin.upper_bounds(), RandomStream(seed));
  };
  const LeastSquaresSearchResult first = run(12);
  const LeastSquaresSearchResult again = run(12);
  EXPECT_EQ(first.argmin, again.argmin);
  EXPECT_EQ(first.evaluations, again.evaluations);
  EXPECT_EQ(first.batches, again.batches);
  EXPECT_GT(first.local_searches, 1) << first.summary();
}

TEST(LeastSquaresSearch, RejectsStepsToControlsTheTwinCannotEvaluate) {
  const Index d = 2;
  const Affine problem(8, d, 13);
  const VectorX lower = VectorX::Constant(d, -20.0);
  const VectorX upper = VectorX::Constant(d, 20.0);
  // No answer beyond u(0) = cut, half a unit short of the free minimum; the start a unit
  // further back.
  const double cut = problem.argmin()(0) - 0.5;
  VectorX start = VectorX::Zero(d);
  start(0) = cut - 1.0;
  const DeviationObjective objective = [&](const Eigen::Ref<const MatrixX>& points,
                                           Eigen::Ref<MatrixX> deviations) {
    for (Index k = 0; k < points.cols(); ++k) {
      deviations.col(k) = problem.a + problem.b * points.col(k);
      if (points(0, k) > cut) deviations(0, k) = std::numeric_limits<double>::quiet_NaN();
    }
  };
  const LeastSquaresSearchResult result =
      LeastSquaresSearch({.evaluations = 80})
          .minimize(objective, 8, start, lower, upper, RandomStream(14));
  EXPECT_TRUE(std::isfinite(result.minimum)) << result.summary();
  EXPECT_LE(result.argmin(0), cut);
  EXPECT_LT(result.minimum, problem.quality(start));
}

TEST(LeastSquaresSearch, ANonFiniteStartIsAnError) {
  const DeviationObjective nan = [](const Eigen::Ref<const MatrixX>&, Eigen::Ref<MatrixX> out) {
    out.setConstant(std::numeric_limits<double>::quiet_NaN());
  };
  const VectorX lower = VectorX::Constant(2, -1.0);
  const VectorX upper = VectorX::Constant(2, 1.0);
  EXPECT_THAT(
      [&] {
        (void)LeastSquaresSearch().minimize(nan, 3, VectorX::Zero(2), lower, upper,
                                            RandomStream(1));
      },
      ThrowsMessage<NonFiniteError>(HasSubstr("deviations: the objective answered non-finite")));
}

TEST(LeastSquaresSearch, PassesTheObjectivesErrorsOn) {
  const DeviationObjective failing = [](const Eigen::Ref<const MatrixX>&, Eigen::Ref<MatrixX>) {
    throw std::runtime_error("solver crashed");
  };
  const VectorX lower = VectorX::Constant(2, -1.0);
  const VectorX upper = VectorX::Constant(2, 1.0);
  EXPECT_THAT(
      [&] {
        (void)LeastSquaresSearch().minimize(failing, 3, VectorX::Zero(2), lower, upper,
                                            RandomStream(1));
      },
      ThrowsMessage<std::runtime_error>(HasSubstr("solver crashed")));
}

TEST(LeastSquaresSearch, BadArgumentsNameTheirRule) {
  const DeviationObjective zero = [](const Eigen::Ref<const MatrixX>&, Eigen::Ref<MatrixX> out) {
    out.setZero();
  };
  const LeastSquaresSearch search;
  const VectorX lower = VectorX::Constant(2, -1.0);
  const VectorX upper = VectorX::Constant(2, 1.0);
  EXPECT_THAT(
      [&] { (void)search.minimize(zero, 0, VectorX::Zero(2), lower, upper, RandomStream(1)); },
      ThrowsMessage<InvalidArgumentError>(HasSubstr("key_points: value is 0")));
  EXPECT_THAT(
      [&] { (void)search.minimize(zero, 3, VectorX(), VectorX(), VectorX(), RandomStream(1)); },
      ThrowsMessage<InvalidArgumentError>(HasSubstr("start: value is empty")));
  EXPECT_THAT(
      [&] {
        (void)search.minimize(zero, 3, VectorX::Constant(2, 2.0), lower, upper, RandomStream(1));
      },
      ThrowsMessage<InvalidArgumentError>(HasSubstr("start(0)")));
  EXPECT_THAT(
      [&] { (void)search.minimize(zero, 3, VectorX::Zero(2), upper, upper, RandomStream(1)); },
      ThrowsMessage<InvalidArgumentError>(HasSubstr("rule: lower < upper")));
}

TEST(LeastSquaresSearchOptions, EachRuleNamesItsField) {
  const auto problem = [](LeastSquaresSearchOptions options) {
    return options.validate().value_or("");
  };
  EXPECT_EQ(problem({}), "");
  EXPECT_THAT(problem({.evaluations = 0}), HasSubstr("evaluations: value is 0"));
  EXPECT_THAT(problem({.difference_step = 0.0}), HasSubstr("difference_step: value is 0"));
  EXPECT_THAT(problem({.difference_step = 0.6}), HasSubstr("difference_step: value is 0.6"));
  EXPECT_THAT(problem({.restart_spread = -0.1}), HasSubstr("restart_spread: value is -0.1"));
  EXPECT_THAT(problem({.agreeing_restarts = -1}), HasSubstr("agreeing_restarts: value is -1"));
  EXPECT_THAT(problem({.agreement = 0.0}), HasSubstr("agreement: value is 0"));
  EXPECT_THAT(problem({.final_step = 0.0}), HasSubstr("final_step: value is 0"));
  EXPECT_THAT(problem({.initial_damping = 0.0}), HasSubstr("initial_damping: value is 0"));
  EXPECT_THAT(problem({.max_damping = 1e-4}), HasSubstr("max_damping: value is 0.0001"));
  EXPECT_THAT([] { (void)LeastSquaresSearch({.evaluations = 0}); },
              ThrowsMessage<InvalidArgumentError>(HasSubstr("LeastSquaresSearchOptions")));
}

TEST(LeastSquaresStatus, NamesItsValues) {
  EXPECT_EQ(to_string(LeastSquaresStatus::converged), "converged");
  EXPECT_EQ(to_string(LeastSquaresStatus::budget_spent), "budget_spent");
}

}  // namespace
}  // namespace twincal::least_squares_search_test
