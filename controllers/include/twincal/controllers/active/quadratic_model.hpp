#pragma once
/// @file
/// `QuadraticModel<N>`: a local model of the squared quality around a centre v0,
///   Q²(x, v) ≈ c + 2 gᵀ(v − v0) + (v − v0)ᵀ H (v − v0),
/// the shape of an RMS deviation that depends affinely on the locator adjustment (a compliant
/// assembly: y = A x + B u + c gives Q² = |y|²/n exactly, with H = BᵀB/n the same for every
/// assembly). With it the paper's measurement h(δu; x, u) = Q(x, u − δu) (eq. 5b) becomes, after
/// squaring, a quadratic form in δu whose Gaussian moments are exact (quadratic_moments.hpp).

#include <Eigen/Core>

#include "twincal/core/eigen.hpp"

namespace twincal {

template <int N>
struct QuadraticModel {
  Vector<N> center;         ///< v0, where the model was fitted (the individualized control u0)
  double value = 0.0;       ///< c = Q²(x, v0)
  Vector<N> half_gradient;  ///< g = ∇Q²(v0)/2
  SquareMatrix<N> hessian;  ///< H = ∇²Q²/2 (symmetric)

  [[nodiscard]] Index dimension() const noexcept { return center.size(); }

  /// The model's Q²(x, v).
  template <typename Derived>
  [[nodiscard]] double operator()(const Eigen::MatrixBase<Derived>& control) const {
    double linear = 0.0;
    double quadratic = 0.0;
    const Index d = dimension();
    // Summed in place: no temporary, so a dynamic-size model does not allocate.
    for (Index j = 0; j < d; ++j) {
      const double e_j = control(j) - center(j);
      linear += half_gradient(j) * e_j;
      double row = 0.0;
      for (Index k = 0; k < d; ++k) row += hessian(k, j) * (control(k) - center(k));
      quadratic += e_j * row;
    }
    return value + 2.0 * linear + quadratic;
  }
};

}  // namespace twincal
