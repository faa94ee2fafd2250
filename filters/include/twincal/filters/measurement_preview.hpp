#pragma once
/// @file
/// `MeasurementPreview<N, M>`: what a sigma-point filter's update would do for given inputs,
/// computed before the measurement z is known. Everything in the update that does not depend on
/// z is here, so `commit(preview, z)` only adds K·(z − ẑ) and evaluates nothing.

#include <cstdint>

#include <Eigen/Core>

#include "twincal/core/cholesky.hpp"
#include "twincal/core/eigen.hpp"

namespace twincal {

template <int N, int M>
struct MeasurementPreview {
  /// γ_i = h(χ_i; inputs) at the filter's current sigma points.
  Vector<M> measurements;
  /// ẑ = Σ Wm_i γ_i, the predicted measurement.
  double predicted_measurement = 0.0;
  /// Pzz = Σ Wc_i (γ_i − ẑ)², the spread of h over the points (without R).
  double measurement_variance = 0.0;
  /// S = Pzz + R, the predicted variance of z (innovation variance).
  double innovation_variance = 0.0;
  /// Pxz = Σ Wc_i (χ_i − x⁻)(γ_i − ẑ).
  Vector<N> cross_covariance;
  /// K = Pxz / S.
  Vector<N> gain;
  /// P⁺, the posterior covariance (independent of z).
  SquareMatrix<N> posterior_covariance;
  /// L⁺, its lower Cholesky factor (the next sigma points are drawn from it).
  SquareMatrix<N> posterior_factor;
  /// What the factorization of P⁺ had to repair (standard form; `none` in square-root form).
  CholeskyReport factorization;
  /// The filter state revision the preview belongs to: commit refuses a stale preview.
  std::uint64_t revision = 0;
};

}  // namespace twincal
