#include "twincal/sheet_metal/constrained_solver.hpp"

#include <vector>

#include <gtest/gtest.h>

#include "twincal/core/error.hpp"

namespace twincal::constrained_solver_test {
namespace {

// Three springs in a chain, 0 — 1 — 2, each of stiffness k_i between consecutive dofs.
Eigen::SparseMatrix<double> chain(double k01, double k12) {
  Eigen::MatrixXd k = Eigen::MatrixXd::Zero(3, 3);
  k(0, 0) += k01;
  k(1, 1) += k01;
  k(0, 1) -= k01;
  k(1, 0) -= k01;
  k(1, 1) += k12;
  k(2, 2) += k12;
  k(1, 2) -= k12;
  k(2, 1) -= k12;
  return k.sparseView();
}

TEST(ConstrainedSolver, PrescribedValuesAndTies) {
  // e0 = 1 and e2 − e1 = 0.5: dof 1 is the only unknown, ½k01(e1 − 1)² is all the variable
  // energy (the 1—2 spring keeps its length), so e1 = 1 unloaded.
  const ConstrainedSolver solver(chain(1.0, 3.0), {{0, -1}, {2, 1}});
  const Eigen::Vector2d values(1.0, 0.5);
  const VectorX e = solver.solve(values);
  EXPECT_NEAR(e(0), 1.0, 1e-14);
  EXPECT_NEAR(e(1), 1.0, 1e-14);
  EXPECT_NEAR(e(2), 1.5, 1e-14);
  // A load of 2 on dof 2 pulls dof 1 along the tie: k01 (e1 − 1) = 2.
  const Eigen::Vector3d load(0.0, 0.0, 2.0);
  const VectorX loaded = solver.solve(values, load);
  EXPECT_NEAR(loaded(1), 3.0, 1e-13);
  EXPECT_NEAR(loaded(2), 3.5, 1e-13);
}

TEST(ConstrainedSolver, RejectsMechanismsAndBadConstraints) {
  EXPECT_THROW(ConstrainedSolver(chain(1.0, 1.0), {{1, 0}}), InvalidArgumentError);  // floats
  EXPECT_THROW(ConstrainedSolver(chain(1.0, 1.0), {{0, -1}, {0, -1}}), InvalidArgumentError);
  EXPECT_THROW((void)ConstrainedSolver(chain(1.0, 1.0), {{0, -1}, {2, 1}}).solve(VectorX::Zero(3)),
               DimensionMismatchError);
  EXPECT_THROW(ConstrainedSolver(chain(1.0, 1.0), {{0, -1}, {1, 0}}), InvalidArgumentError);
  EXPECT_THROW(ConstrainedSolver(chain(1.0, 1.0), {{5, -1}}), InvalidArgumentError);
}

}  // namespace
}  // namespace twincal::constrained_solver_test
