#pragma once
/// @file
/// The pieces of the unscented transform (over the sigma points of the paper's eq. (11)) that
/// SigmaPointFilter and SquareRootSigmaPointFilter share: propagating points through a state model,
/// weighted moments, and the measurement statistics of a preview. Every function checks what it
/// consumes for finiteness and allocates nothing once its outputs and buffers have their sizes.

#include <cmath>
#include <stdexcept>
#include <string>
#include <string_view>

#include <fmt/format.h>
#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/fixed_size_dispatch.hpp"
#include "twincal/core/validate.hpp"
#include "twincal/filters/fixed_size_kernels.hpp"
#include "twincal/filters/measurement_preview.hpp"
#include "twincal/filters/state_model.hpp"

namespace twincal {

namespace detail {

template <typename Derived>
[[noreturn, gnu::cold, gnu::noinline]] void throw_first_non_finite_point(
    std::string_view name, const Eigen::MatrixBase<Derived>& points, std::string_view rule) {
  for (Index c = 0; c < points.cols(); ++c) {
    for (Index r = 0; r < points.rows(); ++r) {
      if (std::isfinite(points(r, c))) continue;
      throw NonFiniteError(std::string(name),
                           fmt::format("{}: entry {} of sigma point {} is {}; rule: {}", name, r, c,
                                       points(r, c), rule));
    }
  }
  throw std::logic_error("throw_first_non_finite_point: called on finite points");
}

template <typename Values>
[[noreturn, gnu::cold, gnu::noinline]] void throw_first_non_finite_measurement(
    const Eigen::MatrixBase<Values>& values) {
  for (Index i = 0; i < values.size(); ++i) {
    if (std::isfinite(values(i))) continue;
    throw NonFiniteError("measurements",
                         fmt::format("measurements: value at sigma point {} is {}; rule: the "
                                     "measurement function must return finite values",
                                     i, values(i)));
  }
  throw std::logic_error("throw_first_non_finite_measurement: called on finite values");
}

[[noreturn, gnu::cold, gnu::noinline]] inline void throw_innovation_variance_not_positive(
    double measurement_variance, double noise_variance) {
  const double innovation_variance = measurement_variance + noise_variance;
  throw NotPositiveDefiniteError(
      "innovation_variance",
      fmt::format("innovation_variance: S = Pzz + R is {:.6g} (Pzz = {:.6g}, R = {:.6g}); "
                  "rule: must be > 0 (negative sigma-point weights can make Pzz negative)",
                  innovation_variance, measurement_variance, noise_variance),
      innovation_variance);
}

}  // namespace detail

/// Throws NonFiniteError("<name>", …) naming the first sigma point (column) with a NaN or an
/// infinity; `rule` says what should have been finite. The check inlines; the search does not.
template <typename Derived>
void require_finite_points(std::string_view name, const Eigen::MatrixBase<Derived>& points,
                           std::string_view rule) {
  if (all_finite(points)) [[likely]]
    return;
  detail::throw_first_non_finite_point(name, points, rule);
}

/// out.col(i) = f(points.col(i)), passing each point through `state` (the model takes a vector).
/// Throws NonFiniteError when f returns a non-finite value.
template <StateModel SM, int N, int M>
void propagate_points(const SM& model, const Matrix<N, M>& points, Matrix<N, M>& out,
                      Vector<N>& state) {
  for (Index i = 0; i < points.cols(); ++i) {
    state = points.col(i);
    out.col(i) = model.propagate(state);
  }
  require_finite_points("propagated sigma points", out,
                        "the state model must return finite states");
}

/// out = Σ W_i χ_i, the weighted mean of the points (one matrix-vector product).
template <int N, int M>
void weighted_mean(const Matrix<N, M>& points, const Vector<M>& weights, Vector<N>& out) {
  if constexpr (N == Dynamic) {
    // Eigen's GEMV set-up costs more than a small product itself (lazy_product_max_rows).
    if (points.rows() <= lazy_product_max_rows) {
      out.noalias() = points.lazyProduct(weights);
      return;
    }
  }
  out.noalias() = points * weights;
}

/// out = Σ Wc_i (χ_i − about)(χ_i − about)ᵀ, through the caller's n × M buffers `centred` and
/// `weighted` (so that the product is one matrix product and nothing is allocated once they
/// have their sizes).
template <int N, int M>
void weighted_covariance(const Matrix<N, M>& points, const Vector<M>& covariance_weights,
                         const Vector<N>& about, Matrix<N, M>& centred, Matrix<N, M>& weighted,
                         SquareMatrix<N>& out) {
  // Up to max_fixed_dispatch_size rows: one rank-one term per point at compile-time size
  // (fixed_size_kernels.hpp), which a run-time size reaches through the compiled dispatch.
  if constexpr (N == Dynamic) {
    out.resize(points.rows(), points.rows());
    if (kernels::weighted_scatter(points, covariance_weights, about, out)) return;
  } else if constexpr (N <= max_fixed_dispatch_size) {
    kernels::weighted_scatter<N>(points, covariance_weights, about, out);
    return;
  }
  centred = points.colwise() - about;
  weighted = centred * covariance_weights.asDiagonal();
  out.noalias() = weighted * centred.transpose();
}

/// out = Pxz = Σ Wc_i (γ_i − ẑ)(χ_i − x) for the values γ_i at the points χ_i (centred on the
/// mean x), ẑ = `predicted`. Allocates nothing once `out` has n entries.
template <int N, int M>
void cross_covariance(const Matrix<N, M>& points, const Vector<N>& mean,
                      const Vector<M>& covariance_weights, const Vector<M>& values,
                      double predicted, Vector<N>& out) {
  out.resize(points.rows());
  if constexpr (N == Dynamic) {
    if (kernels::cross_covariance(points, covariance_weights, values, predicted, mean, out)) {
      return;
    }
  } else if constexpr (N <= max_fixed_dispatch_size) {
    kernels::cross_covariance<N>(points, covariance_weights, values, predicted, mean, out);
    return;
  }
  // Column by column: a product with the centred points as an expression would need a
  // temporary n × M matrix.
  out.setZero();
  for (Index i = 0; i < points.cols(); ++i) {
    out.noalias() += (covariance_weights(i) * (values(i) - predicted)) * (points.col(i) - mean);
  }
}

/// Fills the z-independent measurement statistics of `preview` from the values γ_i at the
/// points χ_i (centred on the filter's mean x): ẑ, Pzz, S = Pzz + R, Pxz and K = Pxz/S.
/// Allocates nothing once `preview` has the sizes of the points (`values` may be
/// preview.measurements itself).
/// @throws NonFiniteError (a γ_i is not finite), NotPositiveDefiniteError (S <= 0, possible with
///         negative weights).
template <int N, int M, typename Values>
void measurement_statistics(const Matrix<N, M>& points, const Vector<N>& mean,
                            const Vector<M>& mean_weights, const Vector<M>& covariance_weights,
                            const Eigen::MatrixBase<Values>& values, double noise_variance,
                            MeasurementPreview<N, M>& preview) {
  require_dimension("measurements", values.size(), points.cols());
  if (!all_finite(values)) [[unlikely]]
    detail::throw_first_non_finite_measurement(values);
  preview.measurements = values;
  const double predicted = mean_weights.dot(preview.measurements);
  preview.predicted_measurement = predicted;
  preview.measurement_variance =
      (covariance_weights.array() * (preview.measurements.array() - predicted).square()).sum();
  preview.innovation_variance = preview.measurement_variance + noise_variance;
  if (!(preview.innovation_variance > 0.0)) [[unlikely]]
    detail::throw_innovation_variance_not_positive(preview.measurement_variance, noise_variance);
  cross_covariance(points, mean, covariance_weights, preview.measurements, predicted,
                   preview.cross_covariance);
  preview.gain = preview.cross_covariance / preview.innovation_variance;
}

/// log N(y; 0, S) of a scalar innovation, the filter's per-step log-likelihood.
[[nodiscard]] inline double innovation_log_likelihood(double innovation, double variance) {
  constexpr double two_pi = 6.283185307179586476925286766559;
  return -0.5 * (std::log(two_pi * variance) + innovation * innovation / variance);
}

}  // namespace twincal
