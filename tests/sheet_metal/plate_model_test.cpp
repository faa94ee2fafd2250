// ACM plate checks against Kirchhoff theory: rigid-body modes, the simply supported (Navier)
// and clamped square plate under uniform load, and convergence under mesh refinement.

#include "twincal/sheet_metal/plate_model.hpp"

#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Cholesky>

#include "twincal/sheet_metal/constrained_solver.hpp"

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

// Gauss–Legendre rule on [−1, 1] (Newton on P_n from the Chebyshev-like first guess).
void gauss_legendre(int n, std::vector<double>& nodes, std::vector<double>& weights) {
  nodes.assign(static_cast<std::size_t>(n), 0.0);
  weights.assign(static_cast<std::size_t>(n), 0.0);
  for (int i = 0; i < n; ++i) {
    double z = std::cos(std::numbers::pi * (i + 0.75) / (n + 0.5));
    double slope = 1.0;
    for (int iteration = 0; iteration < 100; ++iteration) {
      double p = 1.0;
      double previous = 0.0;
      for (int j = 1; j <= n; ++j) {
        const double next = ((2.0 * j - 1.0) * z * p - (j - 1.0) * previous) / j;
        previous = p;
        p = next;
      }
      slope = n * (z * p - previous) / (z * z - 1.0);
      const double step = p / slope;
      z -= step;
      if (std::abs(step) < 1e-15) break;
    }
    nodes[static_cast<std::size_t>(i)] = z;
    weights[static_cast<std::size_t>(i)] = 2.0 / ((1.0 - z * z) * slope * slope);
  }
}

// φ_k(s) = (1 − s²)² P_2k(s) and its first two derivatives at an interior point s: it and its
// slope vanish at s = ±1 (clamped), and the even Legendre factor keeps the basis well
// conditioned. P'' comes from Legendre's equation.
std::array<double, 3> clamped_basis(int k, double s) {
  const int l = 2 * k;
  double p_lower = 1.0;  // P_{l−1} once the loop has run
  double p = 1.0;        // P_l
  if (l > 0) {
    double a = 1.0;
    double b = s;
    for (int m = 1; m < l; ++m) {
      const double c = ((2.0 * m + 1.0) * s * b - m * a) / (m + 1.0);
      a = b;
      b = c;
    }
    p_lower = a;
    p = b;
  }
  const double one = 1.0 - s * s;
  const double dp = l == 0 ? 0.0 : l * (p_lower - s * p) / one;
  const double ddp = (2.0 * s * dp - l * (l + 1.0) * p) / one;
  const double g = one * one;
  const double dg = -4.0 * s * one;
  const double ddg = 12.0 * s * s - 4.0;
  return {g * p, dg * p + g * dp, ddg * p + 2.0 * dg * dp + g * ddp};
}

// Centre deflection of a clamped square plate under uniform load, divided by q a⁴ / D, by the
// Ritz series w = Σ c_ij φ_i(2x/a) φ_j(2y/a) with `terms` × `terms` coefficients. For a clamped
// plate the energy is D/2 ∫ (Δw)² − q ∫ w (the Gaussian-curvature term integrates to zero), so
// with A_r = ∫ φ_i^(r) φ_j^(r) dx, f_i = ∫ φ_i dx: (A2⊗A0 + A0⊗A2 + 2 A1⊗A1) c = f⊗f (a = 1,
// D = q = 1; x = s/2, so d/dx = 2 d/ds and dx = ds/2). Converges from below as terms grow.
double clamped_ritz_coefficient(int terms) {
  std::vector<double> nodes;
  std::vector<double> weights;
  gauss_legendre(4 * terms + 8, nodes, weights);  // exact for the degree ≤ 4 terms + 6 integrands
  const auto n = static_cast<std::size_t>(terms);
  std::vector<double> a0(n * n, 0.0);
  std::vector<double> a1(n * n, 0.0);
  std::vector<double> a2(n * n, 0.0);
  std::vector<double> f(n, 0.0);
  for (std::size_t q = 0; q < nodes.size(); ++q) {
    std::vector<std::array<double, 3>> phi(n);
    for (std::size_t i = 0; i < n; ++i) phi[i] = clamped_basis(static_cast<int>(i), nodes[q]);
    for (std::size_t i = 0; i < n; ++i) {
      f[i] += 0.5 * weights[q] * phi[i][0];
      for (std::size_t j = 0; j < n; ++j) {
        a0[i * n + j] += 0.5 * weights[q] * phi[i][0] * phi[j][0];
        a1[i * n + j] += 2.0 * weights[q] * phi[i][1] * phi[j][1];
        a2[i * n + j] += 8.0 * weights[q] * phi[i][2] * phi[j][2];
      }
    }
  }
  const auto size = static_cast<Index>(n * n);
  Eigen::MatrixXd k(size, size);
  Eigen::VectorXd load(size);
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = 0; j < n; ++j) {
      const auto row = static_cast<Index>(i * n + j);
      load(row) = f[i] * f[j];
      for (std::size_t p = 0; p < n; ++p) {
        for (std::size_t t = 0; t < n; ++t) {
          k(row, static_cast<Index>(p * n + t)) = a2[i * n + p] * a0[j * n + t] +
                                                  a0[i * n + p] * a2[j * n + t] +
                                                  2.0 * a1[i * n + p] * a1[j * n + t];
        }
      }
    }
  }
  const Eigen::VectorXd c = k.ldlt().solve(load);
  double centre = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = 0; j < n; ++j) {
      centre += c(static_cast<Index>(i * n + j)) * clamped_basis(static_cast<int>(i), 0.0)[0] *
                clamped_basis(static_cast<int>(j), 0.0)[0];
    }
  }
  return centre;
}

// The published value of the same coefficient, 0.00126532 (Taylor & Govindjee, "Solution of
// clamped rectangular plate problems", Commun. Numer. Meth. Engng 20 (2004) 757; Timoshenko &
// Woinowsky-Krieger, Theory of Plates and Shells, Table 35: 0.00126).
constexpr double published_clamped_coefficient = 0.00126532;

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
  return edge == Edge::clamped ? clamped_ritz_coefficient(8) * pressure * std::pow(side, 4) / d
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

TEST(PlateModel, ClampedRitzSeriesConvergesToThePublishedCoefficient) {
  EXPECT_LT(std::abs(clamped_ritz_coefficient(2) / published_clamped_coefficient - 1.0), 1e-2);
  EXPECT_LT(std::abs(clamped_ritz_coefficient(8) / published_clamped_coefficient - 1.0), 1e-5);
  // Converged: two more terms per direction change the eighth digit at most.
  EXPECT_LT(std::abs(clamped_ritz_coefficient(8) / clamped_ritz_coefficient(10) - 1.0), 1e-7);
}

TEST(PlateModel, ClampedSquarePlateMatchesSeriesCoefficient) {
  const double expected = reference(Edge::clamped);
  const double w = fem_centre_deflection(documented_mesh, Edge::clamped);
  EXPECT_LT(std::abs(w / expected - 1.0), 0.02) << w << " vs " << expected;
}

TEST(PlateModel, RefinementConverges) {
  for (const Edge edge : {Edge::simply_supported, Edge::clamped}) {
    const double expected = reference(edge);
    double previous = std::numeric_limits<double>::infinity();
    for (const Index n : {4, 8, 16}) {
      const double error = std::abs(fem_centre_deflection(n, edge) / expected - 1.0);
      EXPECT_LT(error, previous) << "mesh " << n;
      previous = error;
    }
  }
}

}  // namespace
}  // namespace twincal::plate_model_test
