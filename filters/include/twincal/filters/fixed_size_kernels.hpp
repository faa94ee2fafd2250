#pragma once
/// @file
/// The per-step arithmetic of the sigma-point filters written for a compile-time state dimension
/// K, and its run-time-sized entry points.
///
/// Why: Eigen unrolls and vectorizes fixed-size expressions, but runs the same arithmetic over
/// run-time sizes as loops with set-up per call; at the dimensions a filter usually has, a
/// Dynamic-size UKF step cost 1.7× the fixed-size one (docs/benchmarks.md). A filter of
/// run-time dimension n ≤ `max_fixed_dispatch_size` therefore hands these kernels to their
/// compile-time instantiation K = n. The entry points are compiled once, in the filters
/// library (src/fixed_size_kernels.cpp), so the eight instantiations per kernel cost no compile
/// time in the translation units that use a Dynamic filter.
///
/// The kernels are also what fixed sizes up to that bound run: accumulating one rank-one term
/// per point keeps Eigen from sending a 6 × 13 · 13 × 6 product to its blocked GEMM, whose
/// packing costs more than the product (Eigen switches at rows + cols + depth ≥ 20).
///
/// Points are the columns of a K-row matrix; nothing here checks sizes or finiteness: the
/// filters do that before calling.

#include <algorithm>
#include <cmath>

#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/fixed_size_dispatch.hpp"

namespace twincal::kernels {

/// out = Σ_i w_i (x_i − c)(x_i − c)ᵀ over the columns x_i of `points`, one rank-one term per
/// point: the predicted covariance of the unscented transform.
template <int K, typename Points, typename Weights, typename Centre, typename Out>
void weighted_scatter(const Eigen::MatrixBase<Points>& points,
                      const Eigen::MatrixBase<Weights>& weights,
                      const Eigen::MatrixBase<Centre>& centre, Eigen::MatrixBase<Out>& out) {
  static_assert(Points::RowsAtCompileTime == K && Out::RowsAtCompileTime == K);
  const Vector<K> c = centre;
  SquareMatrix<K> sum = SquareMatrix<K>::Zero();
  for (Index i = 0; i < points.cols(); ++i) {
    const Vector<K> d = points.col(i) - c;
    sum.noalias() += (weights(i) * d) * d.transpose();
  }
  out = sum;
}

/// out = Σ_i w_i (γ_i − ẑ)(x_i − c): the state–measurement cross-covariance Pxz of a scalar
/// measurement with values γ_i and mean ẑ = `predicted`.
template <int K, typename Points, typename Weights, typename Values, typename Centre, typename Out>
void cross_covariance(const Eigen::MatrixBase<Points>& points,
                      const Eigen::MatrixBase<Weights>& weights,
                      const Eigen::MatrixBase<Values>& values, double predicted,
                      const Eigen::MatrixBase<Centre>& centre, Eigen::MatrixBase<Out>& out) {
  static_assert(Points::RowsAtCompileTime == K && Out::RowsAtCompileTime == K);
  const Vector<K> c = centre;
  Vector<K> sum = Vector<K>::Zero();
  for (Index i = 0; i < points.cols(); ++i) {
    sum.noalias() += (weights(i) * (values(i) - predicted)) * (points.col(i) - c);
  }
  out = sum;
}

/// The symmetric pairs of a sigma-point set: column first + k is x + s·L_k and column
/// first + K + k is x − s·L_k, for the columns L_k of the factor `lower` (k = 0 … K − 1).
template <int K, typename Mean, typename Lower, typename Points>
void symmetric_pairs(const Eigen::MatrixBase<Mean>& mean, const Eigen::MatrixBase<Lower>& lower,
                     double scale, Index first, Eigen::MatrixBase<Points>& points) {
  static_assert(Points::RowsAtCompileTime == K);
  const Vector<K> x = mean;
  for (Index k = 0; k < K; ++k) {
    const Vector<K> step = scale * lower.col(k);
    points.col(first + k) = x + step;
    points.col(first + K + k) = x - step;
  }
}

/// out(i) = √(q0 + max(eᵢᵀ H eᵢ, 0)) with eᵢ = shift − x_i, for every column x_i of `states`:
/// QuadraticQualityMeasurement's batch (shift = u − a). The max clamps the round-off of a
/// positive semi-definite H.
template <int K, typename Weight, typename Shift, typename States, typename Out>
void quadratic_qualities(const Eigen::MatrixBase<Weight>& weight, double offset,
                         const Eigen::MatrixBase<Shift>& shift,
                         const Eigen::MatrixBase<States>& states, Eigen::MatrixBase<Out>& out) {
  static_assert(States::RowsAtCompileTime == K);
  const SquareMatrix<K> h = weight;
  const Vector<K> s = shift;
  for (Index i = 0; i < states.cols(); ++i) {
    const Vector<K> e = s - states.col(i);
    const Vector<K> he = h.lazyProduct(e);
    out(i) = std::sqrt(offset + std::max(e.dot(he), 0.0));
  }
}

// --- run-time-sized entry points (compiled in the filters library) ------------------------------
// Each runs its kernel with K = n and returns true when 1 <= n <= max_fixed_dispatch_size (n the
// row count of the points or states); otherwise it returns false and touches nothing, and the
// caller runs its own run-time-sized code. Outputs must already have their sizes.

/// weighted_scatter at K = points.rows(); `out` is n × n.
[[nodiscard]] bool weighted_scatter(const MatrixX& points, const VectorX& weights,
                                    const VectorX& centre, MatrixX& out);

/// cross_covariance at K = points.rows(); `out` has n entries.
[[nodiscard]] bool cross_covariance(const MatrixX& points, const VectorX& weights,
                                    const VectorX& values, double predicted, const VectorX& centre,
                                    VectorX& out);

/// symmetric_pairs at K = mean.size().
[[nodiscard]] bool symmetric_pairs(Eigen::Ref<const VectorX> mean, Eigen::Ref<const MatrixX> lower,
                                   double scale, Index first, Eigen::Ref<MatrixX> points);

/// quadratic_qualities at K = states.rows().
[[nodiscard]] bool quadratic_qualities(const MatrixX& weight, double offset,
                                       Eigen::Ref<const VectorX> shift,
                                       Eigen::Ref<const MatrixX> states, Eigen::Ref<VectorX> out);

}  // namespace twincal::kernels
