#pragma once
/// @file
/// Cholesky factorization with documented repair policies for covariances that round-off or a
/// model has pushed out of the positive-definite cone.
///
/// Policies (`CholeskyOptions::repair`):
/// - `none`: a failed factorization throws NotPositiveDefiniteError with the smallest
///   eigenvalue in the message.
/// - `jitter`: add ε·I, ε = jitter_initial · s with s the mean |diagonal|, growing by
///   jitter_growth up to jitter_attempts times; the ε used is reported.
/// - `nearest_pd`: replace P by the nearest symmetric positive-definite matrix in the
///   Frobenius norm (Higham 1988), i.e. clip its eigenvalues at
///   eigenvalue_floor · λ_max; the number of clipped eigenvalues is reported.
/// Only the lower triangle of the input is read (as Eigen's LLT does): filters that leave P
/// slightly asymmetric factor what they would factor anyway.

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>

#include <fmt/format.h>
#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Eigenvalues>

#include "twincal/core/cholesky_factor.hpp"
#include "twincal/core/eigen.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/fixed_size_dispatch.hpp"
#include "twincal/core/named_enum.hpp"
#include "twincal/core/options.hpp"
#include "twincal/core/validate.hpp"

namespace twincal {

/// What to do when a matrix to factor is not numerically positive definite.
enum class CovarianceRepair {
  none,        ///< throw NotPositiveDefiniteError
  jitter,      ///< add a growing multiple of the identity
  nearest_pd,  ///< clip eigenvalues (nearest SPD matrix in the Frobenius norm)
};

/// The policies' spellings, for to_string and parse_enum (named_enum.hpp).
[[nodiscard]] constexpr auto name_table(std::type_identity<CovarianceRepair>) noexcept {
  return std::to_array<NameEntry<CovarianceRepair>>({{CovarianceRepair::none, "none"},
                                                     {CovarianceRepair::jitter, "jitter"},
                                                     {CovarianceRepair::nearest_pd, "nearest_pd"}});
}

struct CholeskyOptions {
  CovarianceRepair repair = CovarianceRepair::none;
  double jitter_initial = 1e-12;    ///< first ε relative to the mean |diagonal|
  double jitter_growth = 10.0;      ///< factor between successive ε
  int jitter_attempts = 10;         ///< how many ε to try before giving up
  double eigenvalue_floor = 1e-12;  ///< nearest_pd: smallest kept eigenvalue relative to λ_max

  [[nodiscard]] std::optional<std::string> validate() const {
    return first_problem({rule::positive_finite("jitter_initial", jitter_initial),
                          rule::finite_above("jitter_growth", jitter_growth, 1.0),
                          rule::at_least("jitter_attempts", jitter_attempts, 1),
                          rule::in_open("eigenvalue_floor", eigenvalue_floor, 0.0, 1.0)});
  }
};

/// What a factorization had to do to succeed.
struct CholeskyReport {
  CovarianceRepair applied = CovarianceRepair::none;  ///< `none` when P factored as given
  double jitter = 0.0;                                ///< ε added to the diagonal (jitter policy)
  Index clipped_eigenvalues = 0;  ///< eigenvalues raised to the floor (nearest_pd policy)
  /// Smallest eigenvalue of the input, computed only when a repair was needed (NaN otherwise).
  double smallest_eigenvalue = std::numeric_limits<double>::quiet_NaN();

  [[nodiscard]] bool repaired() const noexcept { return applied != CovarianceRepair::none; }
};

template <int N>
struct CholeskyResult {
  CholeskyFactor<N> factor;
  CholeskyReport report;
};

namespace detail {

template <int N>
[[nodiscard]] bool try_llt(const SquareMatrix<N>& m, SquareMatrix<N>& lower) {
  const Eigen::LLT<SquareMatrix<N>, Eigen::Lower> llt(m);
  if (llt.info() != Eigen::Success) return false;
  lower = llt.matrixL();
  // LLT accepts tiny positive pivots that underflow to a zero diagonal in L.
  return (lower.diagonal().array() > 0.0).all();
}

[[noreturn]] inline void throw_not_pd(std::string_view name, double lambda_min,
                                      std::string_view detail) {
  throw NotPositiveDefiniteError(
      std::string(name),
      fmt::format("{}: Cholesky factorization failed{}: smallest eigenvalue is {:.6g}; rule: "
                  "must be positive definite",
                  name, detail, lambda_min),
      lambda_min);
}

/// In-place lower Cholesky factorization of the K × K `a` at compile-time size: a right-looking
/// rank-one update per column over fixed-size blocks, which the compiler unrolls (Eigen's own
/// unblocked kernel runs its blocks at run-time sizes even for a fixed matrix, a GEMV per
/// column). Reads and overwrites the lower triangle, scribbles on the strict upper one.
/// Returns −1 when every pivot was positive, else the column whose pivot was not.
template <int K, int J = 0, typename Square>
[[nodiscard]] Index llt_in_place_unrolled(Square& a) noexcept {
  if constexpr (J == K) {
    return -1;
  } else {
    const double pivot = a(J, J);
    if (!(pivot > 0.0)) return J;
    const double root = std::sqrt(pivot);
    a(J, J) = root;
    constexpr int rest = K - J - 1;
    if constexpr (rest > 0) {
      auto column = a.template block<rest, 1>(J + 1, J);
      column /= root;
      a.template block<rest, rest>(J + 1, J + 1).noalias() -= column * column.transpose();
    }
    return llt_in_place_unrolled<K, J + 1>(a);
  }
}

/// The happy path of cholesky_into: copies the lower triangle of `matrix` into `lower` (already
/// n × n), factors it in place and returns true when every pivot was positive and finite, with
/// L's strict upper triangle zeroed; returns false otherwise (`lower` then unspecified). Up to
/// max_fixed_dispatch_size at compile-time size with the unrolled kernel, beyond it with Eigen's
/// in-place kernel (the one LLT::compute runs, without the L1 norm that only rcond() reads).
template <typename Source, typename Target>
[[nodiscard]] bool factor_lower(const Eigen::MatrixBase<Source>& matrix,
                                Eigen::MatrixBase<Target>& lower) {
  constexpr int n_at_compile_time = Target::RowsAtCompileTime;
  lower.template triangularView<Eigen::Lower>() = matrix;
  Index failed = 0;
  if constexpr (n_at_compile_time != Dynamic && n_at_compile_time <= max_fixed_dispatch_size) {
    failed = llt_in_place_unrolled<n_at_compile_time>(lower.derived());
  } else {
    failed = Eigen::internal::llt_inplace<double, Eigen::Lower>::blocked(lower.derived());
  }
  // Positive and finite pivots: the kernels pass NaN pivots and tiny ones that underflow to 0.
  constexpr double infinity = std::numeric_limits<double>::infinity();
  if (failed >= 0 ||
      !(lower.diagonal().array() > 0.0 && lower.diagonal().array() < infinity).all()) {
    return false;
  }
  lower.template triangularView<Eigen::StrictlyUpper>().setZero();
  return true;
}

/// factor_lower at compile-time size n for run-time-sized operands with 1 <= n <=
/// max_fixed_dispatch_size (compiled once, in core's src/cholesky.cpp); nullopt, touching
/// nothing, beyond that size.
[[nodiscard]] std::optional<bool> fixed_size_factor_lower(const MatrixX& matrix, MatrixX& lower);

/// The rare half of cholesky(): `input` (symmetric) has no Cholesky factor; repairs it per
/// `options` or throws. With its eigensolver it costs seconds of compile time per file and
/// size, so the sizes that many files factor are compiled once, in core's src/cholesky.cpp (the
/// declarations below): the run-time size, 1 to 3, and 6.
template <int N>
[[nodiscard]] CholeskyResult<N> repaired_cholesky(const SquareMatrix<N>& input,
                                                  const CholeskyOptions& options,
                                                  std::string_view name) {
  using Square = SquareMatrix<N>;
  Square lower(input.rows(), input.cols());
  const Eigen::SelfAdjointEigenSolver<Square> eigen(input);
  CholeskyReport report;
  report.smallest_eigenvalue = eigen.eigenvalues().minCoeff();

  switch (options.repair) {
    case CovarianceRepair::none:
      detail::throw_not_pd(name, report.smallest_eigenvalue, " (repair policy: none)");

    case CovarianceRepair::jitter: {
      const double diagonal_scale =
          std::max(input.diagonal().cwiseAbs().mean(), std::numeric_limits<double>::min());
      double epsilon = options.jitter_initial * diagonal_scale;
      for (int attempt = 0; attempt < options.jitter_attempts; ++attempt) {
        Square shifted = input;
        shifted.diagonal().array() += epsilon;
        if (detail::try_llt<N>(shifted, lower)) {
          report.applied = CovarianceRepair::jitter;
          report.jitter = epsilon;
          return {CholeskyFactor<N>(lower), report};
        }
        epsilon *= options.jitter_growth;
      }
      detail::throw_not_pd(name, report.smallest_eigenvalue,
                           fmt::format(" after {} jitter attempts up to {:.3g}",
                                       options.jitter_attempts, epsilon / options.jitter_growth));
    }

    case CovarianceRepair::nearest_pd: {
      const double lambda_max = eigen.eigenvalues().maxCoeff();
      if (!(lambda_max > 0.0)) {
        detail::throw_not_pd(name, report.smallest_eigenvalue,
                             " (nearest_pd needs a positive largest eigenvalue)");
      }
      const double floor = options.eigenvalue_floor * lambda_max;
      Vector<N> clipped = eigen.eigenvalues();
      for (Index i = 0; i < clipped.size(); ++i) {
        if (clipped(i) < floor) {
          clipped(i) = floor;
          ++report.clipped_eigenvalues;
        }
      }
      const Square repaired =
          eigen.eigenvectors() * clipped.asDiagonal() * eigen.eigenvectors().transpose();
      if (!detail::try_llt<N>(repaired, lower)) {
        detail::throw_not_pd(name, report.smallest_eigenvalue,
                             " (still not positive definite after clipping eigenvalues)");
      }
      report.applied = CovarianceRepair::nearest_pd;
      return {CholeskyFactor<N>(lower), report};
    }
  }
  detail::throw_not_pd(name, report.smallest_eigenvalue, " (unknown repair policy)");
}

extern template CholeskyResult<Dynamic> repaired_cholesky<Dynamic>(const MatrixX&,
                                                                   const CholeskyOptions&,
                                                                   std::string_view);
extern template CholeskyResult<1> repaired_cholesky<1>(const SquareMatrix<1>&,
                                                       const CholeskyOptions&, std::string_view);
extern template CholeskyResult<2> repaired_cholesky<2>(const SquareMatrix<2>&,
                                                       const CholeskyOptions&, std::string_view);
extern template CholeskyResult<3> repaired_cholesky<3>(const SquareMatrix<3>&,
                                                       const CholeskyOptions&, std::string_view);
extern template CholeskyResult<6> repaired_cholesky<6>(const SquareMatrix<6>&,
                                                       const CholeskyOptions&, std::string_view);

}  // namespace detail

/// Factors the symmetric matrix whose lower triangle is `m` as L Lᵀ, repairing it per
/// `options` when needed. No allocation for fixed sizes when no repair is needed.
/// @throws DimensionMismatchError (not square), NonFiniteError, InvalidArgumentError (options),
///         NotPositiveDefiniteError (not PD and the policy could not or may not repair it).
template <typename Derived>
[[nodiscard]] CholeskyResult<Derived::RowsAtCompileTime> cholesky(
    const Eigen::MatrixBase<Derived>& m, const CholeskyOptions& options = {},
    std::string_view name = "matrix") {
  constexpr int N = Derived::RowsAtCompileTime;
  using Square = SquareMatrix<N>;
  require_valid("CholeskyOptions", options);
  require_square(name, m);
  require_finite(name, m);

  const Square input = m.template selfadjointView<Eigen::Lower>();
  Square lower(input.rows(), input.cols());
  if (detail::try_llt<N>(input, lower)) return {CholeskyFactor<N>(lower), CholeskyReport{}};
  return detail::repaired_cholesky<N>(input, options, name);
}

namespace detail {

/// cholesky_into without the check of `options`, for callers that validated them once where
/// they keep them (a filter's constructor): a filter step factors twice, and re-validating
/// unchanged options was a fifth of a one-dimensional step.
template <int N>
CholeskyReport cholesky_into_validated(SquareMatrix<N>& matrix, SquareMatrix<N>& lower,
                                       const CholeskyOptions& options, std::string_view name);

}  // namespace detail

/// cholesky() into caller-owned storage, for hot loops: `lower` receives L (strict upper part
/// zero), factored in place; when a repair was needed, `matrix` is replaced by the repaired
/// matrix L Lᵀ. Allocates nothing, at any size, when no repair is needed and `lower` already has
/// the size of `matrix`. Only the lower triangle of `matrix` is read, and checked: a NaN or an
/// infinity in it always reaches L's diagonal, so the factor is checked instead of the input and
/// the input is searched (for the message) only on failure.
/// @throws as cholesky(); `lower` is then unspecified and `matrix` unchanged.
template <int N>
CholeskyReport cholesky_into(SquareMatrix<N>& matrix, SquareMatrix<N>& lower,
                             const CholeskyOptions& options = {},
                             std::string_view name = "matrix") {
  require_valid("CholeskyOptions", options);
  return detail::cholesky_into_validated(matrix, lower, options, name);
}

template <int N>
CholeskyReport detail::cholesky_into_validated(SquareMatrix<N>& matrix, SquareMatrix<N>& lower,
                                               const CholeskyOptions& options,
                                               std::string_view name) {
  require_square(name, matrix);
  lower.resize(matrix.rows(), matrix.cols());
  bool factored = false;
  if constexpr (N == Dynamic) {
    const std::optional<bool> fixed = detail::fixed_size_factor_lower(matrix, lower);
    factored = fixed ? *fixed : detail::factor_lower(matrix, lower);
  } else {
    factored = detail::factor_lower(matrix, lower);
  }
  if (factored) return CholeskyReport{};
  // The rare path may allocate: the matrix as read (its lower triangle, mirrored), checked for
  // finiteness and factored with the repair policy.
  const SquareMatrix<N> symmetric = matrix.template selfadjointView<Eigen::Lower>();
  CholeskyResult<N> repaired = cholesky(symmetric, options, name);
  lower = repaired.factor.lower();
  if (repaired.report.repaired()) matrix = repaired.factor.covariance();
  return repaired.report;
}

}  // namespace twincal
