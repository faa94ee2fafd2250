#pragma once
/// @file
/// `RandomWalk<N>`: the offset state model of the paper's eq. (5c),
/// δu*_{t+1} ~ N(δu*_t, Σu): the state is carried over unchanged and gains Σu of variance.

#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/validate.hpp"

namespace twincal {

template <int N>
class RandomWalk {
 public:
  static constexpr int dimension_at_compile_time = N;
  using StateVector = Vector<N>;
  using CovarianceMatrix = SquareMatrix<N>;

  /// Σu = `process_noise` (symmetric positive semi-definite).
  /// @throws DimensionMismatchError, NonFiniteError, InvalidArgumentError,
  ///         NotPositiveDefiniteError.
  explicit RandomWalk(const CovarianceMatrix& process_noise) : process_noise_(process_noise) {
    if constexpr (N != Dynamic)
      require_dimension("process_noise", process_noise_.rows(), N, "rows");
    require_positive_definite("process_noise", process_noise_, /*allow_semidefinite=*/true);
  }

  /// Σu = variance · I (the paper uses 1e-3·I).
  /// @throws InvalidArgumentError when `variance` is negative or not finite.
  [[nodiscard]] static RandomWalk isotropic(Index dimension, double variance) {
    require_finite("variance", variance);
    require_non_negative("variance", variance);
    if constexpr (N != Dynamic) require_dimension("dimension", dimension, N);
    return RandomWalk(CovarianceMatrix::Identity(dimension, dimension) * variance);
  }

  [[nodiscard]] Index dimension() const noexcept { return process_noise_.rows(); }

  /// f(δu) = δu.
  [[nodiscard]] const StateVector& propagate(const StateVector& state) const noexcept {
    return state;
  }

  /// Σu.
  [[nodiscard]] const CovarianceMatrix& process_noise() const noexcept { return process_noise_; }

 private:
  CovarianceMatrix process_noise_;
};

}  // namespace twincal
