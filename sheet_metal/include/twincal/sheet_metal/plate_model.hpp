#pragma once
/// @file
/// `PlateModel`: the global bending stiffness of a flat plate meshed with ACM rectangles.
///
/// Plates are flat in the xy-plane and only out-of-plane deviations are modelled: for a flat
/// plate the in-plane (membrane) dofs decouple from bending in linear theory, and the normal
/// deviation is what scans and the RMS quality measure.

#include <Eigen/SparseCore>

#include "twincal/core/eigen.hpp"
#include "twincal/sheet_metal/acm_plate_element.hpp"
#include "twincal/sheet_metal/plate_mesh.hpp"
#include "twincal/sheet_metal/plate_section.hpp"

namespace twincal {

class PlateModel {
 public:
  using SparseMatrix = Eigen::SparseMatrix<double>;

  /// @throws InvalidArgumentError when the section is invalid.
  PlateModel(PlateMesh mesh, const PlateSection& section);

  [[nodiscard]] const PlateMesh& mesh() const noexcept { return mesh_; }
  [[nodiscard]] const PlateSection& section() const noexcept { return section_; }
  [[nodiscard]] const AcmPlateElement& element() const noexcept { return element_; }
  /// Global stiffness K (dof_count × dof_count, symmetric, singular with the three rigid-body
  /// modes w = a + bx + cy of a free plate).
  [[nodiscard]] const SparseMatrix& stiffness() const noexcept { return stiffness_; }
  /// Consistent nodal loads of a uniform pressure (MPa) over the whole plate.
  [[nodiscard]] VectorX uniform_load(double pressure) const;
  /// Nodal vector (w, θx, θy) of the rigid motion w = a + b x + c y.
  [[nodiscard]] VectorX rigid_motion(double a, double b, double c) const;

 private:
  PlateMesh mesh_;
  PlateSection section_;
  AcmPlateElement element_;
  SparseMatrix stiffness_;
};

}  // namespace twincal
