// The staged joining process against a direct, stage-by-stage simulation that solves each
// stage's full Lagrange (KKT) system and releases the clamp and gun forces explicitly; and why
// the process needs more than that: with a release onto a nominal 3-point frame and
// translation-only welds the final shape does not depend on the locator adjustment.

#include "twincal/sheet_metal/sheet_metal_process.hpp"

#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/SparseLU>

#include "twincal/core/random_stream.hpp"
#include "twincal/sheet_metal/sheet_metal_twin.hpp"

namespace twincal::sheet_metal_process_test {
namespace {

using SparseMatrix = Eigen::SparseMatrix<double>;

// Rows of a constraint matrix: each row is a list of (dof, coefficient).
using Row = std::vector<std::pair<Index, double>>;

// Solves [K Cᵀ; C 0] [x; λ] = [load; rhs] with a pivoting sparse LU (no elimination tricks).
VectorX solve_kkt(const SparseMatrix& k, const std::vector<Row>& rows, const VectorX& load,
                  const VectorX& rhs) {
  const Index n = k.rows();
  const auto c = static_cast<Index>(rows.size());
  std::vector<Eigen::Triplet<double>> triplets;
  for (Index col = 0; col < k.outerSize(); ++col) {
    for (SparseMatrix::InnerIterator it(k, col); it; ++it) {
      triplets.emplace_back(it.row(), it.col(), it.value());
    }
  }
  for (Index r = 0; r < c; ++r) {
    for (const auto& [dof, coefficient] : rows[static_cast<std::size_t>(r)]) {
      triplets.emplace_back(n + r, dof, coefficient);
      triplets.emplace_back(dof, n + r, coefficient);
    }
  }
  SparseMatrix kkt(n + c, n + c);
  kkt.setFromTriplets(triplets.begin(), triplets.end());
  Eigen::SparseLU<SparseMatrix> lu(kkt);
  EXPECT_EQ(lu.info(), Eigen::Success);
  VectorX right(n + c);
  right << load, rhs;
  const VectorX solution = lu.solve(right);
  return solution.head(n);
}

// The direct staged simulation: clamp (stage 1), close the gaps with the clamps on (stage 2,
// increment from stage 1), weld and release the clamp and gun forces K e2 onto the welded
// assembly resting on its final supports (stage 3, increment from stage 2).
VectorX direct_key_deviation(const SheetMetalProcess& p, const VectorX& fu, const VectorX& fl,
                             const VectorX& u) {
  const SheetMetalLayout& layout = p.layout();
  const SparseMatrix& k = p.stiffness();
  const Index n = k.rows();
  VectorX f(n);
  f << fu, fl;
  const auto w_dof = [&](SheetMetalPart part, Index node) {
    return p.global_dof(part, PlateMesh::dof(node, 0));
  };
  std::vector<Row> locators;
  for (std::size_t i = 0; i < p.locator_nodes().size(); ++i) {
    locators.push_back({{w_dof(layout.locators[i].part, p.locator_nodes()[i]), 1.0}});
  }
  const std::vector<Index>& weld_u = p.weld_nodes(SheetMetalPart::upper);
  const std::vector<Index>& weld_l = p.weld_nodes(SheetMetalPart::lower);
  const VectorX zero = VectorX::Zero(n);

  // Stage 1: locator k at nominal + u_k.
  VectorX rhs1(static_cast<Index>(locators.size()));
  for (std::size_t i = 0; i < locators.size(); ++i) {
    rhs1(static_cast<Index>(i)) = u(static_cast<Index>(i)) - f(locators[i][0].first);
  }
  const VectorX e1 = solve_kkt(k, locators, zero, rhs1);

  // Stage 2: guns close the gaps, clamps hold (zero increment at the locators).
  std::vector<Row> rows2 = locators;
  VectorX rhs2 = VectorX::Zero(static_cast<Index>(locators.size() + weld_u.size()));
  for (std::size_t j = 0; j < weld_u.size(); ++j) {
    const Index a = w_dof(SheetMetalPart::upper, weld_u[j]);
    const Index b = w_dof(SheetMetalPart::lower, weld_l[j]);
    rows2.push_back({{a, 1.0}, {b, -1.0}});
    rhs2(static_cast<Index>(locators.size() + j)) = -((f(a) + e1(a)) - (f(b) + e1(b)));
  }
  const VectorX e2 = e1 + solve_kkt(k, rows2, zero, rhs2);

  // Stage 3: welds tie the increments; the clamp and gun forces K e2 are released.
  std::vector<Row> rows3;
  std::vector<double> rhs3;
  const Index components = layout.weld_tie == WeldTie::translation ? 1 : 3;
  for (std::size_t j = 0; j < weld_u.size(); ++j) {
    for (Index c = 0; c < components; ++c) {
      rows3.push_back({{p.global_dof(SheetMetalPart::upper, PlateMesh::dof(weld_u[j], c)), 1.0},
                       {p.global_dof(SheetMetalPart::lower, PlateMesh::dof(weld_l[j], c)), -1.0}});
      rhs3.push_back(0.0);
    }
  }
  if (layout.final_support == FinalSupport::adjusted_locators) {
    for (const Row& row : locators) {
      rows3.push_back(row);
      rhs3.push_back(0.0);
    }
  } else {
    for (std::size_t s = 0; s < p.support_nodes().size(); ++s) {
      const Index dof = w_dof(layout.supports[s].part, p.support_nodes()[s]);
      rows3.push_back({{dof, 1.0}});
      rhs3.push_back(-(f(dof) + e2(dof)));  // the support is at the nominal height
    }
  }
  const VectorX released = k * e2;
  const VectorX e3 =
      e2 + solve_kkt(k, rows3, -released,
                     Eigen::Map<const VectorX>(rhs3.data(), static_cast<Index>(rhs3.size())));
  VectorX y(p.key_point_count());
  for (std::size_t i = 0; i < p.key_nodes().size(); ++i) {
    const Index dof = w_dof(layout.key_points[i].part, p.key_nodes()[i]);
    y(static_cast<Index>(i)) = f(dof) + e3(dof);
  }
  return y;
}

VectorX random_vector(Index n, RandomStream& stream, double scale) {
  VectorX v(n);
  stream.fill_normal(v);
  return scale * v;
}

class AffineMapMatchesDirectSolve : public ::testing::TestWithParam<SheetMetalCase> {};

TEST_P(AffineMapMatchesDirectSolve, ForRandomPartsAndControls) {
  const SheetMetalLayout layout = SheetMetalTwin::layout_of(GetParam());
  RandomStream stream = RandomStream(11).substream(layout.name);
  const PlateMesh upper_mesh = layout.mesh(SheetMetalPart::upper);
  const PlateMesh lower_mesh = layout.mesh(SheetMetalPart::lower);
  // Rough random nodal vectors (not smooth fields): every dof of the map is exercised.
  std::vector<VectorX> upper{random_vector(upper_mesh.dof_count(), stream, 0.2),
                             random_vector(upper_mesh.dof_count(), stream, 0.2)};
  std::vector<VectorX> lower{random_vector(lower_mesh.dof_count(), stream, 0.2),
                             random_vector(lower_mesh.dof_count(), stream, 0.2)};
  const SheetMetalTwin twin(layout, SheetMetalTwinOptions{}, upper, lower);
  for (const AssemblyId& assembly : twin.assemblies()) {
    const VectorX u = random_vector(twin.control_dimension(), stream, 1.0);
    const VectorX affine = twin.key_deviation(assembly, u);
    const VectorX direct =
        direct_key_deviation(twin.process(), upper[static_cast<std::size_t>(assembly.upper)],
                             lower[static_cast<std::size_t>(assembly.lower)], u);
    EXPECT_LT((affine - direct).norm(), 1e-9 * direct.norm()) << fmt::format("{}", assembly);
    // Q is the RMS of y.
    EXPECT_NEAR(twin.quality(assembly, u),
                direct.norm() / std::sqrt(static_cast<double>(direct.size())),
                1e-9 * direct.norm());
  }
}

INSTANTIATE_TEST_SUITE_P(Cases, AffineMapMatchesDirectSolve,
                         ::testing::Values(SheetMetalCase::body, SheetMetalCase::door));

// The body layout released onto a nominal 3-point frame.
SheetMetalLayout frame_layout(WeldTie tie) {
  SheetMetalLayout layout = SheetMetalLayout::body();
  layout.final_support = FinalSupport::nominal_frame;
  layout.supports = {{"S1", SheetMetalPart::lower, 100.0, 60.0},
                     {"S2", SheetMetalPart::lower, 700.0, 60.0},
                     {"S3", SheetMetalPart::upper, 400.0, 680.0}};
  layout.weld_tie = tie;
  return layout;
}

TEST(SheetMetalProcess, FullReleaseOntoNominalFrameWithTranslationWeldsIgnoresControl) {
  const SheetMetalProcess translation(frame_layout(WeldTie::translation), PlateSection{});
  const SheetMetalProcess rotation(frame_layout(WeldTie::translation_and_rotation), PlateSection{});
  const MatrixX b_translation = translation.control_influence();
  const MatrixX b_rotation = rotation.control_influence();
  // Unit controls move key points by O(1) mm in the clamped state; after this release nothing of
  // it remains but round-off.
  EXPECT_LT(b_translation.cwiseAbs().maxCoeff(), 1e-10);
  // The same fixture with rotation-locking welds does respond (so the check above can fail).
  EXPECT_GT(b_rotation.cwiseAbs().maxCoeff(), 1e-3);
  // And the final shape still depends on the parts (the process is not trivial).
  RandomStream stream(5);
  const VectorX fu = random_vector(translation.dof_count(SheetMetalPart::upper), stream, 0.1);
  const VectorX fl = random_vector(translation.dof_count(SheetMetalPart::lower), stream, 0.1);
  const VectorX u = random_vector(translation.control_dimension(), stream, 1.0);
  const VectorX y0 = translation.key_deviation(fu, fl, VectorX::Zero(u.size()));
  const VectorX y = translation.key_deviation(fu, fl, u);
  EXPECT_GT(y0.norm(), 1e-2);
  EXPECT_LT((y - y0).norm(), 1e-9);
}

TEST(SheetMetalProcess, RejectsBadInputs) {
  const SheetMetalProcess process(SheetMetalLayout::body(), PlateSection{});
  const VectorX fu = VectorX::Zero(process.dof_count(SheetMetalPart::upper));
  const VectorX fl = VectorX::Zero(process.dof_count(SheetMetalPart::lower));
  EXPECT_THROW((void)process.key_deviation(fu, fl, VectorX::Zero(3)), DimensionMismatchError);
  EXPECT_THROW((void)process.key_deviation(VectorX::Zero(5), fl, VectorX::Zero(12)),
               DimensionMismatchError);
  // Collinear translation-only welds on a 3-point frame leave a hinge: rejected, not solved.
  SheetMetalLayout hinge = frame_layout(WeldTie::translation);
  for (Vector<2>& weld : hinge.welds) weld(1) = 360.0;
  EXPECT_THROW(SheetMetalProcess(hinge, PlateSection{}), InvalidArgumentError);
}

}  // namespace
}  // namespace twincal::sheet_metal_process_test
