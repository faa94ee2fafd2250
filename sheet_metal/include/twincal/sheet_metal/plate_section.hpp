#pragma once
/// @file
/// `PlateSection`: material and thickness of a thin isotropic plate (units mm, N, MPa).

#include <optional>
#include <string>

#include "twincal/core/eigen.hpp"
#include "twincal/core/options.hpp"

namespace twincal {

/// Isotropic elastic plate section; defaults are mild steel sheet of 0.8 mm.
struct PlateSection {
  double young_modulus = 210000.0;  ///< E in MPa
  double poisson_ratio = 0.3;       ///< ν
  double thickness = 0.8;           ///< t in mm

  [[nodiscard]] std::optional<std::string> validate() const {
    return first_problem({rule::positive_finite("young_modulus", young_modulus),
                          rule::in_open("poisson_ratio", poisson_ratio, -1.0, 0.5),
                          rule::positive_finite("thickness", thickness)});
  }

  /// Flexural rigidity D = E t³ / (12 (1 − ν²)) in N·mm.
  [[nodiscard]] double flexural_rigidity() const noexcept {
    return young_modulus * thickness * thickness * thickness /
           (12.0 * (1.0 - poisson_ratio * poisson_ratio));
  }

  /// The bending constitutive matrix: moments (Mx, My, Mxy) = D_b · curvatures
  /// (κx, κy, 2κxy) with κx = −∂²w/∂x², κy = −∂²w/∂y², κxy = −∂²w/∂x∂y.
  [[nodiscard]] SquareMatrix<3> bending_matrix() const noexcept {
    const double d = flexural_rigidity();
    SquareMatrix<3> m;
    m << d, d * poisson_ratio, 0.0, d * poisson_ratio, d, 0.0, 0.0, 0.0,
        d * 0.5 * (1.0 - poisson_ratio);
    return m;
  }
};

}  // namespace twincal
