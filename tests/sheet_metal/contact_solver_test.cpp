#include "twincal/sheet_metal/contact_solver.hpp"

#include <cmath>
#include <cstdint>
#include <optional>
#include <string>

#include <gtest/gtest.h>
#include <Eigen/QR>

#include "twincal/core/error.hpp"
#include "twincal/core/random_stream.hpp"

namespace twincal::contact_solver_test {
namespace {

struct Lcp {
  VectorX force;
  VectorX gap;
};

// The LCP by enumeration of the 2^p closed sets: on each set S solve C_SS f_S = −q_S (minimum
// norm, so singular sets are tried too) and keep the first (f, g) with f >= 0, g >= 0 and
// f_S solving the set's equations. A solvable LCP with positive semi-definite C has a solution
// whose closed set is non-singular, so the enumeration finds one.
std::optional<Lcp> brute_force(const MatrixX& c, const VectorX& q) {
  const Index p = q.size();
  const double scale = 1.0 + q.cwiseAbs().maxCoeff();
  for (std::uint32_t mask = 0; mask < (1U << p); ++mask) {
    std::vector<Index> closed;
    for (Index k = 0; k < p; ++k) {
      if ((mask >> k) & 1U) closed.push_back(k);
    }
    VectorX force = VectorX::Zero(p);
    if (!closed.empty()) {
      const auto n = static_cast<Index>(closed.size());
      MatrixX block(n, n);
      VectorX rhs(n);
      for (Index i = 0; i < n; ++i) {
        rhs(i) = -q(closed[static_cast<std::size_t>(i)]);
        for (Index j = 0; j < n; ++j) {
          block(i, j) = c(closed[static_cast<std::size_t>(i)], closed[static_cast<std::size_t>(j)]);
        }
      }
      const VectorX solution = block.completeOrthogonalDecomposition().solve(rhs);
      if ((block * solution - rhs).norm() > 1e-9 * scale) continue;
      for (Index i = 0; i < n; ++i) force(closed[static_cast<std::size_t>(i)]) = solution(i);
    }
    const VectorX gap = q + c * force;
    if (force.minCoeff() >= -1e-9 * scale && gap.minCoeff() >= -1e-9 * scale) {
      return Lcp{force, gap};
    }
  }
  return std::nullopt;
}

MatrixX random_positive_definite(Index p, RandomStream& stream) {
  MatrixX a(p, p);
  stream.fill_normal(a);
  return a * a.transpose() + 0.05 * MatrixX::Identity(p, p);
}

VectorX random_vector(Index p, RandomStream& stream) {
  VectorX v(p);
  stream.fill_normal(v);
  return v;
}

Lcp solve(const ContactSolver& solver, const VectorX& q, ContactSolverSummary* summary = nullptr) {
  Lcp out{VectorX(q.size()), VectorX(q.size())};
  const ContactSolverSummary s = solver.solve(q, out.force, out.gap);
  if (summary != nullptr) *summary = s;
  return out;
}

class ContactSolverMethods : public ::testing::TestWithParam<ContactSolverMethod> {
 protected:
  [[nodiscard]] ContactSolverOptions options() const { return {.method = GetParam()}; }
};

TEST_P(ContactSolverMethods, MatchBruteForceOnRandomPositiveDefiniteProblems) {
  RandomStream stream(101);
  for (int trial = 0; trial < 300; ++trial) {
    const Index p = 1 + trial % 7;
    const MatrixX c = random_positive_definite(p, stream);
    const VectorX q = random_vector(p, stream);
    const std::optional<Lcp> expected = brute_force(c, q);
    ASSERT_TRUE(expected.has_value()) << "a positive definite LCP always has a solution";
    ContactSolverSummary summary;
    const Lcp found = solve(ContactSolver(c, options()), q, &summary);
    EXPECT_EQ(summary.status, ContactSolverStatus::solved);
    // Positive definite: the solution is unique.
    EXPECT_LT((found.force - expected->force).cwiseAbs().maxCoeff(), 1e-8) << "trial " << trial;
    EXPECT_LT((found.gap - expected->gap).cwiseAbs().maxCoeff(), 1e-8) << "trial " << trial;
    EXPECT_GE(found.force.minCoeff(), 0.0);
    EXPECT_GE(found.gap.minCoeff(), -1e-9);
    EXPECT_LT(summary.residual, 1e-9);
    EXPECT_LT(summary.complementarity, 1e-9);
    Index closed = 0;
    for (Index k = 0; k < p; ++k) closed += found.force(k) > 0.0 ? 1 : 0;
    EXPECT_EQ(summary.closed, closed);
  }
}

TEST_P(ContactSolverMethods, MatchBruteForceOnSemidefiniteProblems) {
  // C = AᵀA of rank r < p and g⁰ = Aᵀb in its range (a mechanism-free, solvable problem): the
  // gaps and the displacements C f are unique even where the forces are not.
  RandomStream stream(202);
  for (int trial = 0; trial < 200; ++trial) {
    const Index p = 2 + trial % 6;
    const Index rank = 1 + trial % (p - 1);
    MatrixX a(rank, p);
    stream.fill_normal(a);
    const MatrixX c = a.transpose() * a;
    const VectorX q = a.transpose() * random_vector(rank, stream);
    const std::optional<Lcp> expected = brute_force(c, q);
    ASSERT_TRUE(expected.has_value());
    ContactSolverSummary summary;
    const Lcp found = solve(ContactSolver(c, options()), q, &summary);
    EXPECT_LT((found.gap - expected->gap).cwiseAbs().maxCoeff(), 1e-8) << "trial " << trial;
    EXPECT_LT((c * found.force - c * expected->force).cwiseAbs().maxCoeff(), 1e-8);
    EXPECT_GE(found.force.minCoeff(), 0.0);
    EXPECT_GE(found.gap.minCoeff(), -1e-9);
  }
}

TEST_P(ContactSolverMethods, AllOpenNeedsNoSolve) {
  RandomStream stream(3);
  const MatrixX c = random_positive_definite(6, stream);
  const VectorX q = random_vector(6, stream).cwiseAbs();
  ContactSolverSummary summary;
  const Lcp found = solve(ContactSolver(c, options()), q, &summary);
  EXPECT_EQ(found.force, VectorX::Zero(6));
  EXPECT_EQ(found.gap, q);
  EXPECT_EQ(summary.iterations, 0);
  EXPECT_EQ(summary.closed, 0);
  EXPECT_EQ(summary.residual, 0.0);
}

TEST_P(ContactSolverMethods, AllClosedRecoversTheForces) {
  // g⁰ = −C f* with f* > 0: every contact closes with exactly f*.
  RandomStream stream(4);
  for (const Index p : {1, 5, 12}) {
    const MatrixX c = random_positive_definite(p, stream);
    const VectorX target = random_vector(p, stream).cwiseAbs().array() + 0.1;
    ContactSolverSummary summary;
    const Lcp found = solve(ContactSolver(c, options()), -c * target, &summary);
    EXPECT_LT((found.force - target).cwiseAbs().maxCoeff(), 1e-9 * (1.0 + target.maxCoeff()));
    EXPECT_LT(found.gap.cwiseAbs().maxCoeff(), 1e-9 * (1.0 + (c * target).cwiseAbs().maxCoeff()));
    EXPECT_EQ(summary.closed, p);
    if (GetParam() == ContactSolverMethod::active_set) {
      EXPECT_GE(summary.iterations, p);  // one contact closes per solve
    } else if (p > 1) {
      // Pivoting closes what penetrates at once; here not all do, so a few rounds.
      EXPECT_LT(summary.iterations, p);
    }
  }
}

TEST(ContactSolver, BlockPivotingNeedsFewSolves) {
  // Many contacts closing at once: block pivoting takes a few rounds, the active-set method at
  // least one solve per closed contact; both give the same forces.
  RandomStream stream(12);
  const Index p = 40;
  const MatrixX c = random_positive_definite(p, stream);
  const VectorX q = random_vector(p, stream);
  ContactSolverSummary pivoting;
  ContactSolverSummary active;
  const Lcp a = solve(ContactSolver(c), q, &pivoting);
  const Lcp b = solve(ContactSolver(c, {.method = ContactSolverMethod::active_set}), q, &active);
  EXPECT_LT((a.force - b.force).cwiseAbs().maxCoeff(), 1e-8 * (1.0 + b.force.maxCoeff()));
  EXPECT_GT(active.closed, 5);
  EXPECT_GE(active.iterations, active.closed);
  EXPECT_LT(pivoting.iterations, active.iterations);
}

TEST(ContactSolver, EmptyAndZeroProblemsAreTrivial) {
  const ContactSolver empty(MatrixX(0, 0));
  VectorX none(0);
  VectorX force(0);
  VectorX gap(0);
  EXPECT_EQ(empty.solve(none, force, gap).closed, 0);
  const ContactSolver one(MatrixX::Constant(1, 1, 2.0));
  VectorX f(1);
  VectorX g(1);
  EXPECT_EQ(one.solve(VectorX::Zero(1), f, g).iterations, 0);
  EXPECT_EQ(f(0), 0.0);
}

TEST_P(ContactSolverMethods, AWorkspaceIsReusableAndTheResultDeterministic) {
  RandomStream stream(5);
  const MatrixX c = random_positive_definite(9, stream);
  const ContactSolver solver(c, options());
  ContactSolver::Workspace workspace(9);
  VectorX force(9);
  VectorX gap(9);
  for (int trial = 0; trial < 20; ++trial) {
    const VectorX q = random_vector(9, stream);
    (void)solver.solve(q, force, gap, workspace);
    const Lcp fresh = solve(solver, q);
    EXPECT_EQ(force, fresh.force);  // bit for bit: the method always starts cold
    EXPECT_EQ(gap, fresh.gap);
  }
}

TEST(ContactSolver, TheIterationLimitIsATypedErrorWithTheSummary) {
  RandomStream stream(6);
  const MatrixX c = random_positive_definite(5, stream);
  const VectorX target = VectorX::Constant(5, 1.0);
  const ContactSolver solver(c, {.method = ContactSolverMethod::active_set, .max_iterations = 2});
  EXPECT_EQ(solver.iteration_limit(), 2);
  EXPECT_EQ(ContactSolver(c).iteration_limit(), 24);
  VectorX force(5);
  VectorX gap(5);
  try {
    (void)solver.solve(-c * target, force, gap);
    FAIL() << "expected ContactSolverError";
  } catch (const ContactSolverError& error) {
    EXPECT_EQ(error.summary().status, ContactSolverStatus::iteration_limit);
    EXPECT_EQ(error.summary().iterations, 2);
    EXPECT_EQ(error.argument(), "contact");
    EXPECT_NE(std::string(error.what()).find("rule: must solve within the iteration limit 2"),
              std::string::npos)
        << error.what();
  }
}

TEST_P(ContactSolverMethods, AProblemWithoutSolutionIsSingular) {
  // g1 + g2 = −0.5 whatever f: no f gives g >= 0.
  MatrixX c(2, 2);
  c << 1.0, -1.0, -1.0, 1.0;
  const ContactSolver solver(c, options());
  VectorX force(2);
  VectorX gap(2);
  try {
    (void)solver.solve(Vector<2>(-1.0, 0.5), force, gap);
    FAIL() << "expected ContactSolverError";
  } catch (const ContactSolverError& error) {
    EXPECT_EQ(error.summary().status, ContactSolverStatus::singular);
    EXPECT_EQ(error.argument(), "compliance");
  }
  // A contact that cannot move (zero compliance) pressed into penetration.
  const ContactSolver rigid(MatrixX::Zero(1, 1), options());
  VectorX f(1);
  VectorX g(1);
  EXPECT_THROW((void)rigid.solve(VectorX::Constant(1, -1.0), f, g), ContactSolverError);
  EXPECT_NO_THROW((void)rigid.solve(VectorX::Constant(1, 1.0), f, g));
}

TEST(ContactSolver, RefusesBadInput) {
  RandomStream stream(7);
  const MatrixX c = random_positive_definite(3, stream);
  EXPECT_THROW(ContactSolver(MatrixX::Identity(3, 2)), DimensionMismatchError);
  MatrixX asymmetric = c;
  asymmetric(0, 1) += 1.0;
  EXPECT_THROW(ContactSolver{asymmetric}, InvalidArgumentError);
  EXPECT_THROW(ContactSolver(-c), NotPositiveDefiniteError);
  MatrixX not_finite = c;
  not_finite(1, 1) = std::nan("");
  EXPECT_THROW(ContactSolver{not_finite}, NonFiniteError);
  try {
    (void)ContactSolver(c, {.tolerance = 0.0});
    FAIL();
  } catch (const InvalidArgumentError& error) {
    EXPECT_EQ(std::string(error.what()),
              "options: tolerance: value is 0; rule: must lie in (0, 1)");
  }
  try {
    (void)ContactSolver(c, {.max_iterations = -1});
    FAIL();
  } catch (const InvalidArgumentError& error) {
    EXPECT_EQ(std::string(error.what()),
              "options: max_iterations: value is -1; rule: must be >= 0 (0: 4 (p + 1))");
  }
  const ContactSolver solver(c);
  VectorX force(3);
  VectorX gap(3);
  VectorX short_force(2);
  EXPECT_THROW((void)solver.solve(VectorX::Zero(2), force, gap), DimensionMismatchError);
  EXPECT_THROW((void)solver.solve(VectorX::Zero(3), short_force, gap), DimensionMismatchError);
  ContactSolver::Workspace small(2);
  EXPECT_THROW((void)solver.solve(VectorX::Zero(3), force, gap, small), DimensionMismatchError);
  VectorX nan_gap = VectorX::Zero(3);
  nan_gap(2) = std::nan("");
  try {
    (void)solver.solve(nan_gap, force, gap);
    FAIL();
  } catch (const NonFiniteError& error) {
    EXPECT_EQ(std::string(error.what()),
              "unloaded_gap: entry 2 is nan; rule: every entry must be finite");
  }
}

INSTANTIATE_TEST_SUITE_P(BothMethods, ContactSolverMethods,
                         ::testing::Values(ContactSolverMethod::block_pivoting,
                                           ContactSolverMethod::active_set));

}  // namespace
}  // namespace twincal::contact_solver_test
