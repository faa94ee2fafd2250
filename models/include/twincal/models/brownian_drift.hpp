#pragma once
/// @file
/// `BrownianDrift<N>`: the filter's own process model as a scenario, eq. (5c):
///   δu*_{t+1} = δu*_t + w_t,   w_t ~ N(0, Σu),
/// drawn as w_t = S ξ_t with ξ_t ~ N(0, I) from the given stream and S the symmetric square
/// root of Σu. The square root (not a Cholesky factor) accepts a semi-definite Σu, e.g. zero
/// variance for locators that do not drift.

#include <algorithm>
#include <cmath>
#include <utility>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>

#include "twincal/core/eigen.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/core/validate.hpp"

namespace twincal {

template <int N>
class BrownianDrift {
 public:
  using OffsetVector = Vector<N>;
  using CovarianceMatrix = SquareMatrix<N>;

  /// Starts at `initial` with increments N(0, `covariance`) drawn from `stream`.
  /// @throws DimensionMismatchError, NonFiniteError, InvalidArgumentError,
  ///         NotPositiveDefiniteError (Σu must be positive semi-definite).
  BrownianDrift(const OffsetVector& initial, const CovarianceMatrix& covariance,
                RandomStream stream)
      : offset_(initial), stream_(std::move(stream)) {
    require_normal_parameters("initial", initial, covariance);
    const Eigen::SelfAdjointEigenSolver<CovarianceMatrix> solver(covariance);
    const OffsetVector roots = solver.eigenvalues().cwiseMax(0.0).cwiseSqrt();
    square_root_ = solver.eigenvectors() * roots.asDiagonal() * solver.eigenvectors().transpose();
    noise_.resize(initial.size());
  }

  [[nodiscard]] Index dimension() const noexcept { return offset_.size(); }
  [[nodiscard]] Index time() const noexcept { return time_; }
  /// δu*_t.
  [[nodiscard]] const OffsetVector& offset() const noexcept { return offset_; }
  /// S with S Sᵀ = Σu.
  [[nodiscard]] const CovarianceMatrix& square_root() const noexcept { return square_root_; }

  /// δu*_{t+1} = δu*_t + S ξ_t.
  void advance() {
    stream_.fill_normal(noise_);
    offset_.noalias() += square_root_ * noise_;
    ++time_;
  }

 private:
  OffsetVector offset_;
  CovarianceMatrix square_root_;
  OffsetVector noise_;
  RandomStream stream_;
  Index time_ = 0;
};

}  // namespace twincal
