// ACM plate checks against Kirchhoff theory: rigid-body modes, the simply supported (Navier)
// and clamped square plate under uniform load, and convergence under mesh refinement.

#include "twincal/models/plate_model.hpp"

#include <array>
#include <cmath>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include "twincal/models/constrained_solver.hpp"

namespace twincal::plate_model_test {
namespace {

constexpr double side = 500.0;         // mm
constexpr double pressure = 1e-3;      // MPa
constexpr Index documented_mesh = 16;  // elements per side for the 2 % check

// Navier's double series for the centre deflection of a simply supported a × a plate:
// w = 16 q / (π⁶ D) Σ_{m,n odd} sin(mπ/2) sin(nπ/2) / (m n (m²/a² + n²/a²)²).
double navier_centre_deflection(double a, double q, double d) {
  double sum = 0.0;
  for (int m = 1; m < 400; m += 2) {
    for (int n = 1; n < 400; n += 2) {
      const double sign = ((m + n) / 2) % 2 == 1 ? 1.0 : -1.0;  // sin(mπ/2) sin(nπ/2)
      const double k = (m * m + n * n) / (a * a);
      sum += sign / (m * n * k * k);
    }
  }
  return 16.0 * q / (std::pow(std::numbers::pi, 6) * d) * sum;
}

// Clamped square plate: w_centre = α q a⁴ / D with α = 0.00126532 (Taylor & Govindjee,
// "Solution of clamped rectangular plate problems", Commun. Numer. Meth. Engng 20 (2004) 757;
// Timoshenko & Woinowsky-Krieger, Theory of Plates and Shells, Table 35, give 0.00126).
constexpr double clamped_coefficient = 0.00126532;

// Scalar loop: GCC 12 -O3 reports a false null dereference for Eigen's norm() of some dynamic
// vectors here.
double euclidean(const VectorX& v) {
  double sum = 0.0;
  for (Index i = 0; i < v.size(); ++i) sum += v(i) * v(i);
  return std::sqrt(sum);
}

enum class Edge { simply_supported, clamped };

double fem_centre_deflection(Index n, Edge edge) {
  const PlateSection section;
  const PlateModel model(
      PlateMesh(n, n, side / static_cast<double>(n), side / static_cast<double>(n)), section);
  const PlateMesh& mesh = model.mesh();
  std::vector<LinearConstraint> constraints;
  for (Index node = 0; node < mesh.node_count(); ++node) {
    const Index i = mesh.column_of(node);
    const Index j = mesh.row_of(node);
    const bool on_x_edge = i == 0 || i == n;  // edges x = const: ∂w/∂y = θx vanishes along them
    const bool on_y_edge = j == 0 || j == n;  // edges y = const: ∂w/∂x = −θy vanishes
    if (!on_x_edge && !on_y_edge) continue;
    constraints.push_back({PlateMesh::dof(node, 0)});
    if (edge == Edge::clamped || on_x_edge) constraints.push_back({PlateMesh::dof(node, 1)});
    if (edge == Edge::clamped || on_y_edge) constraints.push_back({PlateMesh::dof(node, 2)});
  }
  const ConstrainedSolver solver(model.stiffness(), constraints);
  const VectorX e =
      solver.solve(VectorX::Zero(solver.constraint_count()), model.uniform_load(pressure));
  return e(PlateMesh::dof(mesh.node(n / 2, n / 2), 0));
}

double reference(Edge edge) {
  const double d = PlateSection{}.flexural_rigidity();
  return edge == Edge::clamped ? clamped_coefficient * pressure * std::pow(side, 4) / d
                               : navier_centre_deflection(side, pressure, d);
}

TEST(PlateModel, RigidBodyModesCarryNoEnergy) {
  const PlateModel model(PlateMesh(7, 5, 30.0, 20.0, -40.0, 15.0), PlateSection{});
  const double norm = model.stiffness().norm();
  for (const auto& [a, b, c] : {std::array{1.0, 0.0, 0.0}, std::array{0.3, 0.01, 0.0},
                                std::array{-0.2, 0.0, -0.02}, std::array{0.5, 0.003, 0.007}}) {
    const VectorX r = model.rigid_motion(a, b, c);
    const VectorX force = model.stiffness() * r;
    const double residual = euclidean(force);
    const double size = euclidean(r);
    EXPECT_LT(residual, 1e-10 * norm * size) << a << " " << b << " " << c;
  }
  // A bending mode does carry energy (so the check above can fail).
  VectorX bent = VectorX::Zero(model.mesh().dof_count());
  for (Index node = 0; node < model.mesh().node_count(); ++node) {
    const double x = model.mesh().x(node);
    bent(PlateMesh::dof(node, 0)) = 1e-3 * x * x;
    bent(PlateMesh::dof(node, 2)) = -2e-3 * x;
  }
  const VectorX bending_force = model.stiffness() * bent;
  const double bending = euclidean(bending_force);
  const double size = euclidean(bent);
  EXPECT_GT(bending, 1e-6 * norm * size);
}

TEST(PlateModel, StiffnessIsSymmetric) {
  const PlateModel model(PlateMesh(3, 2, 25.0, 40.0), PlateSection{});
  const Eigen::SparseMatrix<double> k = model.stiffness();
  const Eigen::SparseMatrix<double> transposed = k.transpose();
  EXPECT_LT((k - transposed).norm(), 1e-12 * k.norm());
}

TEST(PlateModel, SimplySupportedSquarePlateMatchesNavierSeries) {
  const double expected = reference(Edge::simply_supported);
  // The series itself: the classical coefficient 0.00406 q a⁴ / D (Timoshenko, Table 8).
  EXPECT_NEAR(expected * PlateSection{}.flexural_rigidity() / (pressure * std::pow(side, 4)),
              0.00406, 5e-6);
  const double w = fem_centre_deflection(documented_mesh, Edge::simply_supported);
  EXPECT_LT(std::abs(w / expected - 1.0), 0.02) << w << " vs " << expected;
}

TEST(PlateModel, ClampedSquarePlateMatchesSeriesCoefficient) {
  const double expected = reference(Edge::clamped);
  const double w = fem_centre_deflection(documented_mesh, Edge::clamped);
  EXPECT_LT(std::abs(w / expected - 1.0), 0.02) << w << " vs " << expected;
}

TEST(PlateModel, RefinementConverges) {
  for (const Edge edge : {Edge::simply_supported, Edge::clamped}) {
    const double expected = reference(edge);
    double previous = INFINITY;
    for (const Index n : {4, 8, 16}) {
      const double error = std::abs(fem_centre_deflection(n, edge) / expected - 1.0);
      EXPECT_LT(error, previous) << "mesh " << n;
      previous = error;
    }
  }
}

}  // namespace
}  // namespace twincal::plate_model_test
