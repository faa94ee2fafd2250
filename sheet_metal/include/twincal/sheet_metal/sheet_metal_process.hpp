#pragma once
/// @file
/// `SheetMetalProcess`: the staged joining of two compliant parts, linear FEM with the method of
/// influence coefficients (Liu & Hu 1997). All unknowns are elastic displacements e = (total
/// shape) − (free shape f), stacked as [upper part dofs, lower part dofs]; K = diag(K_U, K_L).
///
/// 1. Clamp: each part is pressed onto its locators, w_total = nominal (0) + u_k at locator k:
///    e_w(locator k) = u_k − f_w(locator k).
/// 2. Weld: guns close the gap at every weld point, w_total,U = w_total,L:
///    e2 = argmin ½ eᵀ K e  s.t.  the locator constraints and e_w,U − e_w,L = f_w,L − f_w,U at the
///    welds. (With bilateral, linear constraints the clamp state of stage 1 needs no separate
///    solve: stage 2's state depends only on its own constraints.)
/// 3. Release: clamps and guns let go. The welds keep the relative displacement (and, with
///    rotation-locking welds, the relative rotation) they had when formed, and the assembly
///    rests on its final supports:
///    e3 = argmin ½ eᵀ K e  s.t.  T (e − e2) = 0 at the welds and, per `FinalSupport`, either the
///    adjusted locators (e_w = u − f_w there) or three nominal supports (e_w = −f_w there).
///    This is the equilibrium K e3 = (weld and support reactions) reached by removing the clamp
///    and gun forces K e2 from the welded assembly.
/// The output is the total deviation y = f_w + e3_w at the key points (the quality Q = RMS(y)).
/// Each stage is one `ConstrainedSolver` factorization, reused for every f and u.

#include <vector>

#include <Eigen/SparseCore>

#include "twincal/core/eigen.hpp"
#include "twincal/sheet_metal/constrained_solver.hpp"
#include "twincal/sheet_metal/plate_model.hpp"
#include "twincal/sheet_metal/plate_section.hpp"
#include "twincal/sheet_metal/sheet_metal_layout.hpp"

namespace twincal {

class SheetMetalProcess {
 public:
  /// Meshes the two parts, assembles their stiffness and factorizes both stages.
  /// @throws InvalidArgumentError when the layout or section is invalid or a stage leaves a
  ///         mechanism (e.g. collinear translation-only welds released onto a 3-point frame).
  SheetMetalProcess(SheetMetalLayout layout, const PlateSection& section);

  [[nodiscard]] const SheetMetalLayout& layout() const noexcept { return layout_; }
  [[nodiscard]] const PlateModel& model(SheetMetalPart part) const noexcept {
    return part == SheetMetalPart::upper ? upper_ : lower_;
  }
  [[nodiscard]] Index control_dimension() const noexcept { return layout_.control_dimension(); }
  [[nodiscard]] Index key_point_count() const noexcept { return layout_.key_point_count(); }
  /// Dofs of one part's free shape (3 per node).
  [[nodiscard]] Index dof_count(SheetMetalPart part) const noexcept {
    return model(part).mesh().dof_count();
  }
  /// Stacked dof of a part's local dof: upper dofs first, then lower.
  [[nodiscard]] Index global_dof(SheetMetalPart part, Index local) const noexcept {
    return part == SheetMetalPart::upper ? local : upper_.mesh().dof_count() + local;
  }
  /// The node (in its part's mesh) of locator k, key point i, support s, and of weld j in the
  /// upper and the lower part.
  [[nodiscard]] const std::vector<Index>& locator_nodes() const noexcept { return locator_nodes_; }
  [[nodiscard]] const std::vector<Index>& key_nodes() const noexcept { return key_nodes_; }
  [[nodiscard]] const std::vector<Index>& support_nodes() const noexcept { return support_nodes_; }
  [[nodiscard]] const std::vector<Index>& weld_nodes(SheetMetalPart part) const noexcept {
    return part == SheetMetalPart::upper ? upper_weld_nodes_ : lower_weld_nodes_;
  }
  /// Block-diagonal K of the two parts (stacked dofs).
  [[nodiscard]] const Eigen::SparseMatrix<double>& stiffness() const noexcept { return stiffness_; }

  /// e2, the clamped and welded state (stacked dofs).
  /// @throws DimensionMismatchError for wrong sizes.
  [[nodiscard]] VectorX welded_state(const Eigen::Ref<const VectorX>& upper_free,
                                     const Eigen::Ref<const VectorX>& lower_free,
                                     const Eigen::Ref<const VectorX>& control) const;
  /// e3, the released state (stacked dofs).
  [[nodiscard]] VectorX released_state(const Eigen::Ref<const VectorX>& upper_free,
                                       const Eigen::Ref<const VectorX>& lower_free,
                                       const Eigen::Ref<const VectorX>& control) const;
  /// y: the total deviation f_w + e3_w at the key points (m entries).
  [[nodiscard]] VectorX key_deviation(const Eigen::Ref<const VectorX>& upper_free,
                                      const Eigen::Ref<const VectorX>& lower_free,
                                      const Eigen::Ref<const VectorX>& control) const;
  /// B = ∂y/∂u (m × d), one staged solve per locator with f = 0.
  [[nodiscard]] MatrixX control_influence() const;

 private:
  // The constraints of stage 2 (locators, gap closures) and stage 3 (weld ties, final supports),
  // in the order their values are filled in welded_state / released_state.
  [[nodiscard]] std::vector<LinearConstraint> weld_constraints() const;
  [[nodiscard]] std::vector<LinearConstraint> release_constraints() const;
  void require_inputs(const Eigen::Ref<const VectorX>& upper_free,
                      const Eigen::Ref<const VectorX>& lower_free,
                      const Eigen::Ref<const VectorX>& control) const;
  [[nodiscard]] double free_w(SheetMetalPart part, Index node,
                              const Eigen::Ref<const VectorX>& upper_free,
                              const Eigen::Ref<const VectorX>& lower_free) const;

  SheetMetalLayout layout_;
  PlateModel upper_;
  PlateModel lower_;
  Eigen::SparseMatrix<double> stiffness_;
  std::vector<Index> locator_nodes_;
  std::vector<Index> key_nodes_;
  std::vector<Index> support_nodes_;
  std::vector<Index> upper_weld_nodes_;
  std::vector<Index> lower_weld_nodes_;
  std::vector<Index> tied_components_;  // 0 (w) or 0, 1, 2 (w, θx, θy) per weld
  ConstrainedSolver weld_stage_;
  ConstrainedSolver release_stage_;
};

}  // namespace twincal
