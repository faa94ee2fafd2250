#pragma once
/// @file
/// `CalculixModel`: a lap joint of two compliant sheets (a `SheetMetalLayout`) as a CalculiX
/// input deck, and the key-point deviations read back from its results (docs/calculix.md).
///
/// Each sheet is one layer of C3D8I solids (incompatible modes: they bend like a shell at these
/// aspect ratios; CalculiX expands its S4 shells into the same elements) on the layout's grid,
/// refined `refinement` times. A part's free shape f (the normal deviation w of each node) is
/// its initial geometry: the lower sheet's mid-surface at z = f_L, the upper one's at
/// z = t + g + f_U (t the thickness, g the nominal gap), so the sheets face each other across
/// g + f_U − f_L in the flange. Per control u (one column of `controls`), the paper's joining
/// process (Sec. 2):
///   1. clamp and weld: both face nodes at locator k are held at total deviation u_k
///      (e_z = u_k − f), each part is pinned in-plane at its first two locators (2-1), and the
///      guns close each weld: e_z,U − e_z,L = f_L − f_U through the thickness (an equation with
///      an auxiliary node whose displacement is that gap, so the constraint is inhomogeneous);
///   2. release: clamps and guns let go; the nuggets keep what they were formed with; the
///      assembly rests on its final supports (the adjusted locators, or a nominal frame).
/// Key-point deviation y = f + mean of the two face nodes' e_z, Q = RMS(y) (mm). With frictionless
/// contact the welded state depends only on the weld stage's constraints, not on the clamp-only
/// state before it, so the clamp is not solved on its own (the MIC model's argument,
/// docs/sheet_metal.md).
///
/// Contact: every facing flange node pair but the welds (`flange_contact_pairs`) is a GAPUNI
/// element from the lower sheet's top face to the upper sheet's bottom face, clearance
/// g + f_U − f_L, penalty `gap_stiffness`. CalculiX solves gaps only with NLGEOM, so a contact
/// model is also geometrically nonlinear: Q² is then neither quadratic nor piecewise quadratic.
///
/// All controls of a batch go into one deck, two steps each: the process starts once and the
/// mesh is read once. Each step replaces every boundary condition (*BOUNDARY, OP=NEW), so a
/// column's result does not depend on the columns before it beyond the nonlinear solver's
/// starting point.

#include <cstddef>
#include <string>
#include <vector>

#include "twincal/calculix/calculix_options.hpp"
#include "twincal/calculix/calculix_results.hpp"
#include "twincal/core/eigen.hpp"
#include "twincal/sheet_metal/contact_pairs.hpp"
#include "twincal/sheet_metal/plate_mesh.hpp"
#include "twincal/sheet_metal/sheet_metal_layout.hpp"

namespace twincal {

/// One assembly's two parts: the free normal deviation w (mm) of every node of each part's
/// CalculiX mesh (`CalculixModel::mesh`), row by row.
struct CalculixParts {
  VectorX upper;
  VectorX lower;
};

class CalculixModel {
 public:
  /// @throws InvalidArgumentError for invalid options or layout, a layout whose welds lock
  ///         rotations (not modelled: a nugget is a through-thickness tie of the normal
  ///         displacement), or a part with fewer than two locators (no in-plane pinning).
  CalculixModel(SheetMetalLayout layout, CalculixOptions options);

  /// The layout on the CalculiX grid (element_size divided by the refinement).
  [[nodiscard]] const SheetMetalLayout& layout() const noexcept { return layout_; }
  [[nodiscard]] const CalculixOptions& options() const noexcept { return options_; }
  [[nodiscard]] const PlateMesh& mesh(SheetMetalPart part) const noexcept {
    return part == SheetMetalPart::upper ? upper_mesh_ : lower_mesh_;
  }
  [[nodiscard]] Index control_dimension() const noexcept { return layout_.control_dimension(); }
  [[nodiscard]] Index key_point_count() const noexcept { return layout_.key_point_count(); }
  [[nodiscard]] const std::vector<ContactPair>& contact_pairs() const noexcept { return pairs_; }
  /// Nodes in the deck (both faces of both sheets and one auxiliary node per weld).
  [[nodiscard]] Index deck_node_count() const noexcept;

  /// @throws DimensionMismatchError when a part's size is not its mesh's node count;
  ///         NonFiniteError for a NaN or infinite deviation.
  void require_parts(const CalculixParts& parts) const;
  /// @throws DimensionMismatchError for a control of the wrong size; NonFiniteError for a
  ///         non-finite entry; InvalidArgumentError for an empty batch.
  void require_controls(const Eigen::Ref<const MatrixX>& controls) const;

  /// The deck for one assembly and every column of `controls` (d × k): two steps per column,
  /// the key points printed at the end of each release (total time 2, 4, …, 2k).
  [[nodiscard]] std::string deck(const CalculixParts& parts,
                                 const Eigen::Ref<const MatrixX>& controls) const;

  /// The key-point deviations y (mm) of one release print.
  /// @throws CalculixError{unreadable_results} when the print lacks a key-point node.
  [[nodiscard]] VectorX key_deviations(const CalculixParts& parts, const NodePrint& print) const;

 private:
  [[nodiscard]] Index deck_node(SheetMetalPart part, Index node, Index face) const noexcept;
  [[nodiscard]] Index weld_aux_node(std::size_t weld) const noexcept;
  // The parts as placed in the fixture: the upper one lifted rigidly (a translation in z) until
  // no flange pair or weld starts interpenetrated.
  [[nodiscard]] CalculixParts placed(const CalculixParts& parts) const;
  [[nodiscard]] double free_shape(const CalculixParts& parts, SheetMetalPart part,
                                  Index node) const noexcept;
  void write_model(std::string& out, const CalculixParts& parts) const;
  void write_fixture(std::string& out, const CalculixParts& parts,
                     const Eigen::Ref<const VectorX>& control, bool release) const;

  SheetMetalLayout layout_;
  CalculixOptions options_;
  PlateMesh upper_mesh_;
  PlateMesh lower_mesh_;
  std::vector<ContactPair> pairs_;
  struct PointNode {
    SheetMetalPart part;
    Index node;
  };
  std::vector<PointNode> locator_nodes_;
  std::vector<PointNode> key_nodes_;
  std::vector<PointNode> support_nodes_;
  std::vector<Index> upper_weld_nodes_;
  std::vector<Index> lower_weld_nodes_;
  /// Per part (lower, upper): the node pinned in x and y, the node pinned in one direction,
  /// and that direction (1 = x, 2 = y, CalculiX's dof numbers).
  struct InPlanePins {
    Index both = 0;
    Index one = 0;
    int direction = 2;
  };
  InPlanePins lower_pins_;
  InPlanePins upper_pins_;
};

}  // namespace twincal
