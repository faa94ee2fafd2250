#pragma once
/// @file
/// `AcmPlateElement`: the 12-dof Adini–Clough–Melosh (ACM) rectangular Kirchhoff plate element.
///
/// On a rectangle of size a × b the deflection is the incomplete quartic
///   w(ξ, η) = c1 + c2 ξ + c3 η + c4 ξ² + c5 ξη + c6 η² + c7 ξ³ + c8 ξ²η + c9 ξη² + c10 η³
///             + c11 ξ³η + c12 ξη³
/// in local coordinates centred on the element; the 12 coefficients follow from the nodal values
/// (w, θx = ∂w/∂y, θy = −∂w/∂x) at the four corners. Curvatures κ = −(w_xx, w_yy, 2 w_xy) give
/// the stiffness K = ∫ Bᵀ D_b B dA, integrated exactly with 3 × 3 Gauss points. The element is
/// non-conforming (normal slope jumps across edges) but passes the patch test, so it converges
/// (O(h²) in deflection) and represents rigid-body motion and constant curvature exactly.
/// Corner order: (−a/2, −b/2), (a/2, −b/2), (a/2, b/2), (−a/2, b/2); dof order per corner
/// (w, θx, θy).

#include "twincal/core/eigen.hpp"
#include "twincal/sheet_metal/plate_section.hpp"

namespace twincal {

class AcmPlateElement {
 public:
  using Stiffness = SquareMatrix<12>;
  using Load = Vector<12>;

  /// The element of size `width` × `height` (mm).
  /// @throws InvalidArgumentError when a size is not finite and > 0 or the section is invalid.
  AcmPlateElement(double width, double height, const PlateSection& section);

  /// K_e (12 × 12, N·mm per unit dof).
  [[nodiscard]] const Stiffness& stiffness() const noexcept { return stiffness_; }
  /// Consistent nodal loads of a uniform pressure `pressure` (MPa): ∫ Nᵀ q dA.
  [[nodiscard]] Load pressure_load(double pressure) const noexcept {
    return pressure * unit_pressure_load_;
  }
  /// Shape functions: w(ξ, η) = N(ξ, η) · element dofs, ξ, η local (element centre = 0).
  [[nodiscard]] RowVector<12> shape(double xi, double eta) const noexcept;

 private:
  SquareMatrix<12> coefficients_;  // polynomial coefficients = coefficients_ · nodal dofs
  Stiffness stiffness_;
  Load unit_pressure_load_;
};

}  // namespace twincal
