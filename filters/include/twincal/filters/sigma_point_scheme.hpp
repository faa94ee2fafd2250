#pragma once
/// @file
/// `SigmaPointScheme`: a deterministic rule that replaces N(x, P) by M weighted points (the
/// paper's sigma points S_t with weights W(s_t), eq. (11)). A scheme is a small value type held
/// by the filter as a member; it never allocates and never validates in `generate` (the filter
/// validates once, before it calls).
///
/// Contract for a scheme S (checked by the conformance suite in
/// twincal/filters/testing/sigma_point_scheme_conformance.hpp):
/// - `S::points_at_compile_time(N)`: constexpr number of points for a compile-time dimension
///   (Dynamic when N is);
/// - `num_points(n)`: the number of points M for dimension n;
/// - `weights(n, mean_weights, covariance_weights)`: fills the two weight vectors (length M);
///   throws InvalidArgumentError when the scheme's parameters do not admit dimension n;
/// - `generate(mean, lower, points)`: writes the M points (columns of the pre-sized n × M
///   `points`) for N(mean, L Lᵀ), `lower` = L the lower Cholesky factor of P;
/// - `S::degree`: every polynomial of total degree <= degree is integrated exactly under the
///   Gaussian (3 for the unscented and cubature rules, 5 for the fifth-degree rule);
/// - `S::is_symmetric`: the points come in pairs mirrored about the mean, with equal weights.
/// Σ Wm = 1 and Σ Wc (χ − x)(χ − x)ᵀ = P are required of every scheme.

#include <concepts>
#include <type_traits>

#include <Eigen/Core>

#include "twincal/core/eigen.hpp"

namespace twincal {

template <typename S>
concept SigmaPointScheme = std::copy_constructible<S> &&
    requires(const S& scheme, Index n, const VectorX& mean, const MatrixX& lower, MatrixX& points,
             Eigen::Ref<VectorX> weights) {
  typename std::integral_constant<int, S::points_at_compile_time(3)>;
  typename std::integral_constant<int, S::degree>;
  typename std::bool_constant<S::is_symmetric>;
  { scheme.num_points(n) } -> std::same_as<Index>;
  scheme.weights(n, weights, weights);
  scheme.generate(mean, lower, points);
};

}  // namespace twincal
