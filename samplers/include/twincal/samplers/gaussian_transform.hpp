#pragma once
/// @file
/// `GaussianTransform<N>`: maps points of [0, 1)^d to N(m, P), the paper's candidate proposal
/// "a Sobol sequence … transformed into a sequence from a Gaussian distribution with mean û*_t
/// (eq. (9)) and covariance P_t" (Sec. 2.3.2, approximating eq. (14)):
///
///   x = m + A · Φ⁻¹(clip(u)),   A Aᵀ = P,   clip(u) = min(max(u, ε), 1 − ε).
///
/// The clip keeps the first Sobol point (0) and any coordinate at 0 from becoming −∞; with the
/// default ε = 1e-10 the extreme values are ±6.36 standard deviations. The factor A is
///  - `cholesky`: the lower Cholesky factor (cheapest; coordinate 1 of u drives coordinate 1 of
///    x alone);
///  - `eigen` (PCA): A = V Λ^½ with the eigenvalues in decreasing order, so the first, best
///    distributed coordinates of a low-discrepancy point drive the directions of largest
///    variance.
/// A positive semi-definite P (a degenerate direction) is accepted: when the Cholesky
/// factorization fails, the eigen factor is used instead (factorization() says which was used),
/// negative round-off eigenvalues being set to zero.
///
/// Fixed N transforms column by column without allocating; Dynamic uses one matrix product.

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>

#include <fmt/format.h>
#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Eigenvalues>

#include "twincal/core/eigen.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/named_enum.hpp"
#include "twincal/core/options.hpp"
#include "twincal/core/validate.hpp"
#include "twincal/samplers/normal_quantile.hpp"

namespace twincal {

/// The square root A of P (A Aᵀ = P) used by GaussianTransform.
enum class GaussianFactorization {
  cholesky,  ///< lower Cholesky factor; falls back to eigen for a semi-definite P
  eigen,     ///< A = V Λ^½, eigenvalues decreasing (principal components first)
};

/// The factors' spellings, for to_string and parse_enum (named_enum.hpp).
[[nodiscard]] constexpr auto name_table(std::type_identity<GaussianFactorization>) noexcept {
  return std::to_array<NameEntry<GaussianFactorization>>(
      {{GaussianFactorization::cholesky, "cholesky"}, {GaussianFactorization::eigen, "eigen"}});
}

struct GaussianTransformOptions {
  GaussianFactorization factorization = GaussianFactorization::cholesky;
  /// ε: uniform coordinates are clipped to [ε, 1 − ε] before Φ⁻¹.
  double clip = 1e-10;

  [[nodiscard]] std::optional<std::string> validate() const {
    return rule::in_open("clip", clip, 0.0, 0.5);
  }
};

/// Uniform points → N(mean, covariance) (see the file comment).
template <int N>
class GaussianTransform {
 public:
  using Options = GaussianTransformOptions;
  using Points = Matrix<N, Dynamic>;
  static constexpr int dimension_at_compile_time = N;

  /// Throws DimensionMismatchError (sizes), NonFiniteError (mean or covariance),
  /// InvalidArgumentError (asymmetric covariance, invalid options) or NotPositiveDefiniteError
  /// (covariance with a negative eigenvalue beyond round-off).
  GaussianTransform(const Vector<N>& mean, const SquareMatrix<N>& covariance,
                    GaussianTransformOptions options = {})
      : mean_(mean), factor_(covariance.rows(), covariance.cols()), options_(options) {
    require_valid("options", options);
    require_finite("mean", mean);
    require_square("covariance", covariance);
    require_dimension("covariance", covariance.rows(), mean.size(), "rows");
    require_positive_definite("covariance", covariance, /*allow_semidefinite=*/true);
    if (options.factorization == GaussianFactorization::cholesky) {
      const Eigen::LLT<SquareMatrix<N>> llt(covariance);
      if (llt.info() == Eigen::Success) {
        factor_ = llt.matrixL();
        factorization_ = GaussianFactorization::cholesky;
        return;
      }
    }
    const Eigen::SelfAdjointEigenSolver<SquareMatrix<N>> solver(covariance);
    const Index n = covariance.rows();
    for (Index k = 0; k < n; ++k) {  // decreasing eigenvalues: principal direction first
      const Index source = n - 1 - k;
      factor_.col(k) = solver.eigenvectors().col(source) *
                       std::sqrt(std::max(solver.eigenvalues()(source), 0.0));
    }
    factorization_ = GaussianFactorization::eigen;
  }

  [[nodiscard]] Index dimension() const noexcept { return mean_.size(); }
  [[nodiscard]] const Vector<N>& mean() const noexcept { return mean_; }
  /// A with A Aᵀ = P (lower triangular when factorization() is cholesky).
  [[nodiscard]] const SquareMatrix<N>& factor() const noexcept { return factor_; }
  /// The factorization actually used (eigen after a Cholesky fallback).
  [[nodiscard]] GaussianFactorization factorization() const noexcept { return factorization_; }
  [[nodiscard]] const GaussianTransformOptions& options() const noexcept { return options_; }

  /// Writes the transform of each column of `uniform` (d × count, entries in [0, 1]) to the
  /// same column of `out`; `out` may be `uniform` itself. Throws DimensionMismatchError for
  /// wrong sizes, InvalidArgumentError naming the first entry outside [0, 1] (NaN included);
  /// `out` is untouched when it throws.
  void transform(const Eigen::Ref<const Points>& uniform, Eigen::Ref<Points> out) const {
    require_dimension("uniform", uniform.rows(), dimension(), "rows");
    require_shape("out", out, uniform.rows(), uniform.cols());
    require_unit_interval(uniform);
    const double low = options_.clip;
    const double high = 1.0 - options_.clip;
    const auto quantile = [low, high](double u) {
      return normal_quantile(std::clamp(u, low, high));
    };
    if constexpr (N != Dynamic) {
      Vector<N> z;
      for (Index c = 0; c < uniform.cols(); ++c) {
        for (Index r = 0; r < N; ++r) z(r) = quantile(uniform(r, c));
        if (factorization_ == GaussianFactorization::cholesky) {
          out.col(c).noalias() = mean_ + factor_.template triangularView<Eigen::Lower>() * z;
        } else {
          out.col(c).noalias() = mean_ + factor_ * z;
        }
      }
    } else {
      out = uniform.unaryExpr(quantile);
      if (factorization_ == GaussianFactorization::cholesky) {
        out = factor_.template triangularView<Eigen::Lower>() * out;
      } else {
        out = factor_ * out;
      }
      out.colwise() += mean_;
    }
  }

  /// The transform of `uniform` as a new matrix.
  [[nodiscard]] Points operator()(const Eigen::Ref<const Points>& uniform) const {
    Points out(uniform.rows(), uniform.cols());
    transform(uniform, out);
    return out;
  }

 private:
  static void require_unit_interval(const Eigen::Ref<const Points>& uniform) {
    if ((uniform.array() >= 0.0).all() && (uniform.array() <= 1.0).all()) return;
    for (Index c = 0; c < uniform.cols(); ++c) {
      for (Index r = 0; r < uniform.rows(); ++r) {
        const double u = uniform(r, c);
        if (u >= 0.0 && u <= 1.0) continue;
        throw InvalidArgumentError(
            "uniform",
            fmt::format("uniform: entry ({}, {}) is {}; rule: must lie in [0, 1]", r, c, u));
      }
    }
  }

  Vector<N> mean_;
  SquareMatrix<N> factor_;
  GaussianTransformOptions options_;
  GaussianFactorization factorization_ = GaussianFactorization::cholesky;
};

}  // namespace twincal
