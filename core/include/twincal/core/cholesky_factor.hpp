#pragma once
/// @file
/// `CholeskyFactor<N>`: the lower-triangular square root L of a covariance P = L Lᵀ, the type
/// filters pass around when they need √P (sigma points, square-root filtering).

#include <cmath>
#include <string_view>

#include <fmt/format.h>
#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/validate.hpp"

namespace twincal {

/// The rank-one kernel behind CholeskyFactor::rank_one_update, for callers that keep their own
/// buffers (filters at run-time sizes): turns the lower factor `lower` of P into that of
/// P + sign·x xᵀ (sign = +1 or −1), using `x` as scratch. Returns −1, or the column at which a
/// downdate lost definiteness; `lower` and `x` are then partly updated, so callers that must
/// stay unchanged on failure pass copies. O(n²), allocates nothing.
template <int N>
[[nodiscard]] Index rank_one_update_in_place(SquareMatrix<N>& lower, Vector<N>& x,
                                             double sign) noexcept {
  const Index n = lower.rows();
  for (Index k = 0; k < n; ++k) {
    const double lkk = lower(k, k);
    const double radicand = lkk * lkk + sign * x(k) * x(k);
    if (!(radicand > 0.0)) return k;
    const double r = std::sqrt(radicand);
    const double c = r / lkk;
    const double s = x(k) / lkk;
    const double inverse_c = lkk / r;  // one division per column, not one per entry
    lower(k, k) = r;
    // Scalar loop rather than tail blocks: GCC 12 misreads vectorized size-2 tails as out of
    // bounds (-Warray-bounds), and the update is O(n) per column either way.
    for (Index j = k + 1; j < n; ++j) {
      const double l = (lower(j, k) + sign * s * x(j)) * inverse_c;
      lower(j, k) = l;
      x(j) = c * x(j) - s * l;
    }
  }
  return -1;
}

/// Lower-triangular L with a positive diagonal, so that L Lᵀ is positive definite.
/// Invariant checked on construction and kept by every operation (a failing operation throws
/// and leaves the factor unchanged).
template <int N>
class CholeskyFactor {
 public:
  using MatrixType = SquareMatrix<N>;
  using VectorType = Vector<N>;

  /// Takes the lower triangle of `lower` (the strict upper part must be zero).
  /// @throws DimensionMismatchError, NonFiniteError, InvalidArgumentError (upper part not zero),
  ///         NotPositiveDefiniteError (a diagonal entry is not > 0).
  explicit CholeskyFactor(const MatrixType& lower) : lower_(lower) { check_invariant("L"); }

  /// Dimension n of the factored n × n covariance.
  [[nodiscard]] Index dimension() const noexcept { return lower_.rows(); }

  /// The lower-triangular factor L.
  [[nodiscard]] const MatrixType& lower() const noexcept { return lower_; }

  /// The covariance L Lᵀ.
  [[nodiscard]] MatrixType covariance() const {
    MatrixType p = lower_ * lower_.transpose();
    return p;
  }

  /// log det(L Lᵀ) = 2 Σ log L_ii, stable where det itself would underflow.
  [[nodiscard]] double log_determinant() const {
    return 2.0 * lower_.diagonal().array().log().sum();
  }

  /// Solves (L Lᵀ) x = b.
  template <typename Derived>
  [[nodiscard]] typename Derived::PlainObject solve(const Eigen::MatrixBase<Derived>& b) const {
    require_dimension("b", b.rows(), dimension(), "rows");
    typename Derived::PlainObject x(b);
    lower_.template triangularView<Eigen::Lower>().solveInPlace(x);
    lower_.transpose().template triangularView<Eigen::Upper>().solveInPlace(x);
    return x;
  }

  /// Rank-one update (σ > 0) or downdate (σ < 0): after the call L Lᵀ = old L Lᵀ + σ v vᵀ.
  /// O(n²), no allocation for fixed N.
  /// @throws NotPositiveDefiniteError when a downdate would leave the matrix not positive
  ///         definite; the factor is then unchanged.
  template <typename Derived>
  void rank_one_update(const Eigen::MatrixBase<Derived>& v, double sigma) {
    require_dimension("v", v.size(), dimension());
    require_finite("v", v);
    require_finite("sigma", sigma);
    if (sigma == 0.0) return;
    VectorType x = std::sqrt(std::abs(sigma)) * v;
    MatrixType updated = lower_;
    const Index failed = rank_one_update_in_place(updated, x, sigma > 0.0 ? 1.0 : -1.0);
    if (failed >= 0) {
      // Failure path only: the eigenvalue tells the caller how far from definite it got.
      const MatrixType target = covariance() + sigma * (v * v.transpose());
      const double lambda_min = smallest_eigenvalue(target);
      throw NotPositiveDefiniteError(
          "L",
          fmt::format("L: rank-one downdate by sigma = {:.6g} fails at column {}: L Lᵀ + "
                      "sigma v vᵀ has smallest eigenvalue {:.6g}; rule: the result must stay "
                      "positive definite",
                      sigma, failed, lambda_min),
          lambda_min);
    }
    lower_ = updated;
  }

 private:
  void check_invariant(std::string_view name) const {
    require_square(name, lower_);
    require_finite(name, lower_);
    const Index n = lower_.rows();
    for (Index c = 1; c < n; ++c) {
      for (Index r = 0; r < c; ++r) {
        if (lower_(r, c) != 0.0) {
          throw InvalidArgumentError(
              std::string(name),
              fmt::format("{}: entry ({}, {}) above the diagonal is {}; rule: a Cholesky "
                          "factor is lower triangular",
                          name, r, c, lower_(r, c)));
        }
      }
    }
    for (Index k = 0; k < n; ++k) {
      if (!(lower_(k, k) > 0.0)) {
        throw NotPositiveDefiniteError(
            std::string(name),
            fmt::format("{}: diagonal entry {} is {}; rule: a Cholesky factor has a positive "
                        "diagonal",
                        name, k, lower_(k, k)),
            lower_(k, k));
      }
    }
  }

  MatrixType lower_;
};

}  // namespace twincal
