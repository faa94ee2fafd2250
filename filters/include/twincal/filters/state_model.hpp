#pragma once
/// @file
/// `StateModel`: the process model of a sigma-point filter, x_{t+1} = f(x_t) + w_t with
/// w_t ~ N(0, Q). The paper's is the random walk of eq. (5c) (f = identity, Q = Σu), which
/// models' RandomWalk<N> satisfies without depending on this header.

#include <concepts>
#include <type_traits>

#include <Eigen/Core>

#include "twincal/core/eigen.hpp"

namespace twincal {

/// An Eigen matrix expression of compile-time shape `R` × `C` (either may be Dynamic). Stricter
/// than convertibility: Eigen converts between any sizes and fails only at run time.
template <typename T, int R, int C>
concept EigenMatrixOfShape =
    std::derived_from<std::remove_cvref_t<T>, Eigen::MatrixBase<std::remove_cvref_t<T>>> &&
    std::remove_cvref_t<T>::RowsAtCompileTime == R&& std::remove_cvref_t<T>::ColsAtCompileTime == C;

/// A state model of compile-time dimension `M::dimension_at_compile_time` (N or Dynamic):
/// - `dimension()`: the run-time dimension n;
/// - `propagate(x)`: f(x), an N-vector returned by value or by const reference;
/// - `process_noise()`: Q (N × N, symmetric positive semi-definite).
template <typename M>
concept StateModel = requires {
  { M::dimension_at_compile_time } -> std::convertible_to<int>;
}
&&requires(const M& model, const Vector<M::dimension_at_compile_time>& state) {
  { model.dimension() } -> std::convertible_to<Index>;
  { model.propagate(state) } -> EigenMatrixOfShape<M::dimension_at_compile_time, 1>;
  {
    model.process_noise()
    } -> EigenMatrixOfShape<M::dimension_at_compile_time, M::dimension_at_compile_time>;
};

}  // namespace twincal
