#pragma once
/// @file
/// Eigen aliases used throughout twincal. Every template parameter that is a size accepts
/// `twincal::Dynamic` (= Eigen::Dynamic): fixed sizes give allocation-free hot loops, dynamic
/// sizes give run-time dimensions; both go through the same code.

#include <Eigen/Core>

namespace twincal {

/// Eigen's index type (signed), used for every dimension and element index.
using Index = Eigen::Index;

/// Marker for a size known only at run time.
inline constexpr int Dynamic = Eigen::Dynamic;

/// Column vector of `N` doubles (`N` may be Dynamic).
template <int N>
using Vector = Eigen::Matrix<double, N, 1>;

/// Row vector of `N` doubles (`N` may be Dynamic).
template <int N>
using RowVector = Eigen::Matrix<double, 1, N>;

/// `R` × `C` matrix of doubles, column-major (either size may be Dynamic).
template <int R, int C>
using Matrix = Eigen::Matrix<double, R, C>;

/// `N` × `N` matrix of doubles (a covariance, a factor, a Jacobian).
template <int N>
using SquareMatrix = Matrix<N, N>;

using VectorX = Vector<Dynamic>;
using MatrixX = Matrix<Dynamic, Dynamic>;

/// Compile-time size of a sum of two sizes: Dynamic if either is (e.g. 2N+1 sigma points).
[[nodiscard]] constexpr int size_sum(int a, int b) noexcept {
  return (a == Dynamic || b == Dynamic) ? Dynamic : a + b;
}

/// Compile-time size of a product `k·n`: Dynamic if either is.
[[nodiscard]] constexpr int size_product(int k, int n) noexcept {
  return (k == Dynamic || n == Dynamic) ? Dynamic : k * n;
}

/// The largest row count of a run-time-sized product that twincal evaluates with Eigen's
/// coefficient-based kernel (`lazyProduct`, what a small fixed size gets) instead of its
/// general GEMV / blocked GEMM, whose packing and set-up dominate a product this small. Eigen
/// itself only switches a matrix product when rows + cols + depth < 20, and never a
/// matrix-vector product. The filters' weighted mean and the analytic measurement's single-point
/// He use it; their per-step kernels go further, to compile-time sizes (fixed_size_dispatch.hpp).
inline constexpr Index lazy_product_max_rows = 8;

}  // namespace twincal
