#pragma once
/// @file
/// `StateModel`: the process model of a sigma-point filter, x_{t+1} = f(x_t) + w_t with
/// w_t ~ N(0, Q). The paper's is the random walk of eq. (5c) (f = identity, Q = Σu), which
/// models' RandomWalk<N> satisfies without depending on this header.

#include <concepts>

#include "twincal/core/eigen.hpp"

namespace twincal {

/// A state model of compile-time dimension `M::dimension_at_compile_time` (N or Dynamic):
/// - `dimension()`: the run-time dimension n;
/// - `propagate(x)`: f(x), returned by value or by const reference;
/// - `process_noise()`: Q (n × n, symmetric positive semi-definite).
template <typename M>
concept StateModel = requires {
  { M::dimension_at_compile_time } -> std::convertible_to<int>;
}
&&requires(const M& model, const Vector<M::dimension_at_compile_time>& state) {
  { model.dimension() } -> std::convertible_to<Index>;
  { model.propagate(state) } -> std::convertible_to<Vector<M::dimension_at_compile_time>>;
  { model.process_noise() } -> std::convertible_to<SquareMatrix<M::dimension_at_compile_time>>;
};

}  // namespace twincal
