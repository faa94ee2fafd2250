#include "twincal/sheet_metal/acm_plate_element.hpp"

#include <array>
#include <cmath>

#include <fmt/format.h>
#include <Eigen/LU>

#include "twincal/core/error.hpp"
#include "twincal/core/options.hpp"

namespace twincal {

namespace {

using Row = RowVector<12>;

// The 12 monomials 1, ξ, η, ξ², ξη, η², ξ³, ξ²η, ξη², η³, ξ³η, ξη³ and their derivatives.
Row monomials(double x, double y) {
  Row p;
  p << 1.0, x, y, x * x, x * y, y * y, x * x * x, x * x * y, x * y * y, y * y * y, x * x * x * y,
      x * y * y * y;
  return p;
}

Row monomials_dx(double x, double y) {
  Row p;
  p << 0.0, 1.0, 0.0, 2.0 * x, y, 0.0, 3.0 * x * x, 2.0 * x * y, y * y, 0.0, 3.0 * x * x * y,
      y * y * y;
  return p;
}

Row monomials_dy(double x, double y) {
  Row p;
  p << 0.0, 0.0, 1.0, 0.0, x, 2.0 * y, 0.0, x * x, 2.0 * x * y, 3.0 * y * y, x * x * x,
      3.0 * x * y * y;
  return p;
}

Row monomials_dxx(double x, double y) {
  Row p;
  p << 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 6.0 * x, 2.0 * y, 0.0, 0.0, 6.0 * x * y, 0.0;
  return p;
}

Row monomials_dyy(double x, double y) {
  Row p;
  p << 0.0, 0.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 2.0 * x, 6.0 * y, 0.0, 6.0 * x * y;
  return p;
}

Row monomials_dxy(double x, double y) {
  Row p;
  p << 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 2.0 * x, 2.0 * y, 0.0, 3.0 * x * x, 3.0 * y * y;
  return p;
}

// 3-point Gauss–Legendre rule on [−1, 1]: exact for the degree-4 integrands of K and the
// degree-4 shape functions of the load vector, per direction.
constexpr std::array<double, 3> gauss_weights{5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};
const std::array<double, 3> gauss_points{-std::sqrt(0.6), 0.0, std::sqrt(0.6)};

}  // namespace

AcmPlateElement::AcmPlateElement(double width, double height, const PlateSection& section) {
  if (!(width > 0.0) || !(height > 0.0) || !std::isfinite(width) || !std::isfinite(height)) {
    throw InvalidArgumentError(
        "element size",
        fmt::format("element size: is {} x {} mm; rule: both must be finite and > 0", width,
                    height));
  }
  require_valid("section", section);
  const double ha = 0.5 * width;
  const double hb = 0.5 * height;
  const std::array<double, 4> corner_x{-ha, ha, ha, -ha};
  const std::array<double, 4> corner_y{-hb, -hb, hb, hb};

  // Nodal dofs = C · coefficients: rows (w, θx = ∂w/∂y, θy = −∂w/∂x) per corner.
  SquareMatrix<12> c;
  for (std::size_t k = 0; k < 4; ++k) {
    const Index r = 3 * static_cast<Index>(k);
    c.row(r) = monomials(corner_x[k], corner_y[k]);
    c.row(r + 1) = monomials_dy(corner_x[k], corner_y[k]);
    c.row(r + 2) = -monomials_dx(corner_x[k], corner_y[k]);
  }
  coefficients_ = c.fullPivLu().inverse();

  const SquareMatrix<3> bending = section.bending_matrix();
  stiffness_.setZero();
  unit_pressure_load_.setZero();
  const double jacobian = ha * hb;
  for (std::size_t i = 0; i < 3; ++i) {
    for (std::size_t j = 0; j < 3; ++j) {
      const double x = ha * gauss_points[i];
      const double y = hb * gauss_points[j];
      const double weight = gauss_weights[i] * gauss_weights[j] * jacobian;
      Matrix<3, 12> b;
      b.row(0) = -monomials_dxx(x, y) * coefficients_;
      b.row(1) = -monomials_dyy(x, y) * coefficients_;
      b.row(2) = -2.0 * monomials_dxy(x, y) * coefficients_;
      stiffness_.noalias() += weight * (b.transpose() * bending * b);
      unit_pressure_load_.noalias() += weight * (monomials(x, y) * coefficients_).transpose();
    }
  }
  // Exact in exact arithmetic; symmetrize the round-off so the global matrix is symmetric.
  stiffness_ = (0.5 * (stiffness_ + stiffness_.transpose())).eval();
}

RowVector<12> AcmPlateElement::shape(double xi, double eta) const noexcept {
  return monomials(xi, eta) * coefficients_;
}

}  // namespace twincal
