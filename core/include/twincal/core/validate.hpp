#pragma once
/// @file
/// Argument checks that throw twincal's typed errors. Each message names the argument, the
/// offending value and the rule, e.g.
/// "P: entry (1, 0) is nan; rule: every entry must be finite".
/// The checks read their inputs only, so a caller that validates before mutating keeps the
/// strong exception guarantee.

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>

#include <fmt/format.h>
#include <Eigen/Core>
#include <Eigen/Eigenvalues>

#include "twincal/core/eigen.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/format.hpp"

namespace twincal {

namespace detail {

[[noreturn, gnu::cold, gnu::noinline]] inline void throw_non_finite(std::string_view name,
                                                                    double value) {
  throw NonFiniteError(std::string(name),
                       fmt::format("{}: value is {}; rule: must be finite", name, value));
}

}  // namespace detail

/// Throws NonFiniteError unless `value` is finite. The check inlines; the throw does not.
inline void require_finite(std::string_view name, double value) {
  if (std::isfinite(value)) [[likely]]
    return;
  detail::throw_non_finite(name, value);
}

/// True when every entry of `x` is finite. One vectorised reduction: x·0 is 0 for a finite entry
/// and NaN for a NaN or an infinity, and a NaN survives the sum (2–3× faster than Eigen's
/// allFinite(), which compares x − x with itself; these checks run on every filter step).
template <typename Derived>
[[nodiscard]] bool all_finite(const Eigen::DenseBase<Derived>& x) {
  return x.size() == 0 || (x.derived().array() * 0.0).sum() == 0.0;
}

namespace detail {

// The throwing half of require_finite, kept out of line so that the check itself inlines into
// hot loops as one reduction and a branch.
template <typename Derived>
[[noreturn, gnu::cold, gnu::noinline]] void throw_first_non_finite(
    std::string_view name, const Eigen::DenseBase<Derived>& x) {
  for (Index c = 0; c < x.cols(); ++c) {
    for (Index r = 0; r < x.rows(); ++r) {
      const double value = x(r, c);
      if (std::isfinite(value)) continue;
      const std::string where =
          x.cols() == 1 ? fmt::format("entry {}", r) : fmt::format("entry ({}, {})", r, c);
      throw NonFiniteError(
          std::string(name),
          fmt::format("{}: {} is {}; rule: every entry must be finite", name, where, value));
    }
  }
  throw std::logic_error("throw_first_non_finite: called on finite input");
}

}  // namespace detail

/// Throws NonFiniteError naming the first non-finite entry (row, column) of `x`.
template <typename Derived>
void require_finite(std::string_view name, const Eigen::DenseBase<Derived>& x) {
  if (all_finite(x)) [[likely]]
    return;
  detail::throw_first_non_finite(name, x);
}

/// Throws DimensionMismatchError unless `actual == expected`; `what` says which size
/// ("size", "rows", "columns").
inline void require_dimension(std::string_view name, Index actual, Index expected,
                              std::string_view what = "size") {
  if (actual == expected) return;
  throw DimensionMismatchError(
      std::string(name),
      fmt::format("{}: {} is {}; rule: must equal {}", name, what, actual, expected), actual,
      expected);
}

/// Throws DimensionMismatchError unless `m` is square.
template <typename Derived>
void require_square(std::string_view name, const Eigen::EigenBase<Derived>& m) {
  if (m.rows() == m.cols()) return;
  throw DimensionMismatchError(
      std::string(name),
      fmt::format("{}: is {}x{}; rule: must be square", name, m.rows(), m.cols()), m.cols(),
      m.rows());
}

/// Throws DimensionMismatchError unless `m` is `rows` × `cols`.
template <typename Derived>
void require_shape(std::string_view name, const Eigen::EigenBase<Derived>& m, Index rows,
                   Index cols) {
  if (m.rows() == rows && m.cols() == cols) return;
  throw DimensionMismatchError(
      std::string(name),
      fmt::format("{}: is {}x{}; rule: must be {}x{}", name, m.rows(), m.cols(), rows, cols),
      m.rows() * m.cols(), rows * cols);
}

/// Throws InvalidArgumentError unless `value > 0` (NaN fails).
inline void require_positive(std::string_view name, double value) {
  if (value > 0.0) return;
  throw InvalidArgumentError(std::string(name),
                             fmt::format("{}: value is {}; rule: must be > 0", name, value));
}

/// Throws InvalidArgumentError unless `value >= 0` (NaN fails).
inline void require_non_negative(std::string_view name, double value) {
  if (value >= 0.0) return;
  throw InvalidArgumentError(std::string(name),
                             fmt::format("{}: value is {}; rule: must be >= 0", name, value));
}

/// Throws InvalidArgumentError unless `low <= value <= high` (NaN fails).
inline void require_in_range(std::string_view name, double value, double low, double high) {
  if (value >= low && value <= high) return;
  throw InvalidArgumentError(
      std::string(name),
      fmt::format("{}: value is {}; rule: must lie in [{}, {}]", name, value, low, high));
}

/// Largest |m(i,j) − m(j,i)| relative to the largest |m(i,j)| (0 for a zero matrix).
template <typename Derived>
[[nodiscard]] double relative_asymmetry(const Eigen::MatrixBase<Derived>& m) {
  const double scale = m.cwiseAbs().maxCoeff();
  if (scale == 0.0) return 0.0;
  return (m - m.transpose()).cwiseAbs().maxCoeff() / scale;
}

/// Throws InvalidArgumentError unless `m` is square and symmetric to `tolerance` (relative to
/// its largest entry). Finite entries are checked first.
template <typename Derived>
void require_symmetric(std::string_view name, const Eigen::MatrixBase<Derived>& m,
                       double tolerance = 1e-12) {
  require_square(name, m);
  require_finite(name, m);
  const double asymmetry = relative_asymmetry(m);
  if (asymmetry <= tolerance) return;
  throw InvalidArgumentError(
      std::string(name),
      fmt::format("{}: relative asymmetry max|m - mᵀ|/max|m| is {:.3g}; rule: must be "
                  "symmetric to {:.3g}",
                  name, asymmetry, tolerance));
}

namespace detail {

/// Smallest and largest eigenvalue of a symmetric N × N matrix, by Eigen's self-adjoint solver.
/// Every check of positive definiteness calls it, and the solver's instantiation costs seconds
/// of compile time per file and size, so the sizes that many files check are compiled once, in
/// core's src/validate.cpp (the declarations below): the run-time size, 1 to 3 locators, and 6
/// (the constant-velocity state of 3).
template <int N>
[[nodiscard]] std::pair<double, double> symmetric_eigenvalue_range(
    const SquareMatrix<N>& symmetric) {
  const Eigen::SelfAdjointEigenSolver<SquareMatrix<N>> solver(symmetric, Eigen::EigenvaluesOnly);
  return {solver.eigenvalues().minCoeff(), solver.eigenvalues().maxCoeff()};
}

extern template std::pair<double, double> symmetric_eigenvalue_range<Dynamic>(const MatrixX&);
extern template std::pair<double, double> symmetric_eigenvalue_range<1>(const SquareMatrix<1>&);
extern template std::pair<double, double> symmetric_eigenvalue_range<2>(const SquareMatrix<2>&);
extern template std::pair<double, double> symmetric_eigenvalue_range<3>(const SquareMatrix<3>&);
extern template std::pair<double, double> symmetric_eigenvalue_range<6>(const SquareMatrix<6>&);

}  // namespace detail

/// Smallest and largest eigenvalue of the symmetric part (m + mᵀ)/2. Allocates nothing when
/// `m`'s size is fixed at compile time.
template <typename Derived>
[[nodiscard]] std::pair<double, double> eigenvalue_range(const Eigen::MatrixBase<Derived>& m) {
  constexpr int n = Derived::RowsAtCompileTime != Dynamic ? Derived::RowsAtCompileTime
                                                          : Derived::ColsAtCompileTime;
  const SquareMatrix<n> symmetric = 0.5 * (m + m.transpose());
  return detail::symmetric_eigenvalue_range<n>(symmetric);
}

/// Smallest eigenvalue of the symmetric part (m + mᵀ)/2.
template <typename Derived>
[[nodiscard]] double smallest_eigenvalue(const Eigen::MatrixBase<Derived>& m) {
  return eigenvalue_range(m).first;
}

/// Throws NotPositiveDefiniteError unless the symmetric matrix `m` has all eigenvalues
/// > 0 (`allow_semidefinite = false`) or >= 0 (`true`). A semi-definite matrix computed in
/// floating point has zero eigenvalues that come out as ±(round-off), so the semi-definite rule
/// accepts eigenvalues down to −16·n·ε·max|λ|. Checks shape, finiteness and symmetry first, each
/// with its own error.
template <typename Derived>
void require_positive_definite(std::string_view name, const Eigen::MatrixBase<Derived>& m,
                               bool allow_semidefinite = false, double symmetry_tolerance = 1e-12) {
  require_symmetric(name, m, symmetry_tolerance);
  if (m.rows() == 0) return;
  const auto [lambda_min, lambda_max] = eigenvalue_range(m);
  const double round_off = 16.0 * static_cast<double>(m.rows()) *
                           std::numeric_limits<double>::epsilon() *
                           std::max(std::abs(lambda_min), std::abs(lambda_max));
  const bool ok = allow_semidefinite ? lambda_min >= -round_off : lambda_min > 0.0;
  if (ok) return;
  throw NotPositiveDefiniteError(
      std::string(name),
      fmt::format("{}: smallest eigenvalue is {:.6g}; rule: must be positive {}definite "
                  "(all eigenvalues {} 0)",
                  name, lambda_min, allow_semidefinite ? "semi-" : "",
                  allow_semidefinite ? ">=" : ">"),
      lambda_min);
}

/// Checks the parameters of a normal distribution N(mean, covariance) (a Gaussian's, a drift's
/// start and increments): `mean` finite, and "covariance" a symmetric positive semi-definite
/// matrix of its size, symmetric to `symmetry_tolerance`.
/// @throws NonFiniteError, DimensionMismatchError, InvalidArgumentError (asymmetric),
///         NotPositiveDefiniteError (a negative eigenvalue).
template <typename MeanDerived, typename CovarianceDerived>
void require_normal_parameters(std::string_view mean_name,
                               const Eigen::MatrixBase<MeanDerived>& mean,
                               const Eigen::MatrixBase<CovarianceDerived>& covariance,
                               double symmetry_tolerance = 1e-12) {
  require_finite(mean_name, mean);
  require_shape("covariance", covariance, mean.size(), mean.size());
  require_positive_definite("covariance", covariance, /*allow_semidefinite=*/true,
                            symmetry_tolerance);
}

}  // namespace twincal
