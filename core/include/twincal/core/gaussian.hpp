#pragma once
/// @file
/// `Gaussian<N>`: a multivariate normal N(mean, covariance), the belief a filter holds about the
/// offset δu (the paper's eq. (8): δu*_t ~ N(δû_t, P_t)).

#include <cmath>
#include <numbers>
#include <string_view>

#include <fmt/format.h>
#include <Eigen/Core>

#include "twincal/core/cholesky.hpp"
#include "twincal/core/eigen.hpp"
#include "twincal/core/format.hpp"
#include "twincal/core/validate.hpp"

namespace twincal {

/// A validated normal distribution: finite mean, symmetric positive semi-definite covariance of
/// matching size. Immutable; construct a new one to change it.
template <int N>
class Gaussian {
 public:
  using VectorType = Vector<N>;
  using MatrixType = SquareMatrix<N>;

  /// @throws DimensionMismatchError, NonFiniteError, InvalidArgumentError (asymmetric),
  ///         NotPositiveDefiniteError (a negative eigenvalue).
  Gaussian(VectorType mean, MatrixType covariance)
      : mean_(std::move(mean)), covariance_(std::move(covariance)) {
    require_normal_parameters("mean", mean_, covariance_, /*symmetry_tolerance=*/1e-10);
  }

  [[nodiscard]] Index dimension() const noexcept { return mean_.size(); }
  [[nodiscard]] const VectorType& mean() const noexcept { return mean_; }
  [[nodiscard]] const MatrixType& covariance() const noexcept { return covariance_; }

  /// log N(x; mean, covariance).
  /// @throws NotPositiveDefiniteError for a singular covariance (the density does not exist).
  template <typename Derived>
  [[nodiscard]] double log_density(const Eigen::MatrixBase<Derived>& x) const {
    require_dimension("x", x.size(), dimension());
    require_finite("x", x);
    const CholeskyResult<N> factored = cholesky(covariance_, {}, "covariance");
    const VectorType residual = x - mean_;
    const VectorType whitened =
        factored.factor.lower().template triangularView<Eigen::Lower>().solve(residual);
    const auto n = static_cast<double>(dimension());
    return -0.5 * (whitened.squaredNorm() + factored.factor.log_determinant() +
                   n * std::log(2.0 * std::numbers::pi));
  }

  friend bool operator==(const Gaussian& a, const Gaussian& b) {
    return a.mean_ == b.mean_ && a.covariance_ == b.covariance_;
  }

 private:
  VectorType mean_;
  MatrixType covariance_;
};

}  // namespace twincal

/// Prints "N(mean=[...], covariance=[[...], ...])"; the spec applies to every number.
template <int N, typename Char>
struct fmt::formatter<twincal::Gaussian<N>, Char> {
  constexpr auto parse(fmt::basic_format_parse_context<Char>& ctx) { return matrix_.parse(ctx); }

  template <typename FormatContext>
  auto format(const twincal::Gaussian<N>& g, FormatContext& ctx) const -> decltype(ctx.out()) {
    // One dynamic-size formatter prints both parts with the one parsed spec.
    ctx.advance_to(fmt::format_to(ctx.out(), "N(mean="));
    ctx.advance_to(matrix_.format(twincal::MatrixX(g.mean()), ctx));
    ctx.advance_to(fmt::format_to(ctx.out(), ", covariance="));
    ctx.advance_to(matrix_.format(twincal::MatrixX(g.covariance()), ctx));
    return fmt::format_to(ctx.out(), ")");
  }

 private:
  fmt::formatter<twincal::MatrixX, Char> matrix_;
};
