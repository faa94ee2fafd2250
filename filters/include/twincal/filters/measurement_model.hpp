#pragma once
/// @file
/// `MeasurementModel`: a scalar measurement z = h(x; inputs) + v, v ~ N(0, R), whose external
/// inputs (the paper's assembly x_t and control u_t) are given at update time. The paper's is
/// models' QualityFeedback: h(δu; x, u) = Q(x, u − δu) (eq. 5b, Assumption 1).
///
/// `BatchMeasurementModel` adds the optional hook that evaluates every sigma point in one call,
/// the place where an expensive black box parallelises. `evaluate_measurements` uses it when
/// present and otherwise calls `measure` once per point.

#include <concepts>

#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/validate.hpp"

namespace twincal {

/// A scalar measurement model of compile-time state dimension `M::dimension_at_compile_time`:
/// - `typename M::Inputs`: what the measurement depends on besides the state;
/// - `measure(x, inputs)`: h(x; inputs);
/// - `noise_variance()`: R = σz².
template <typename M>
concept MeasurementModel = requires {
  typename M::Inputs;
  { M::dimension_at_compile_time } -> std::convertible_to<int>;
}
&&requires(const M& model, const Vector<M::dimension_at_compile_time>& state,
           const typename M::Inputs& inputs) {
  { model.measure(state, inputs) } -> std::convertible_to<double>;
  { model.noise_variance() } -> std::convertible_to<double>;
};

/// A MeasurementModel with `measure_batch(states, inputs, out)`: `states` is n × k with one state
/// per column, `out` receives the k values h(states.col(i); inputs).
template <typename M>
concept BatchMeasurementModel = MeasurementModel<M> &&
    requires(const M& model, const Eigen::Ref<const MatrixX>& states,
             const typename M::Inputs& inputs, Eigen::Ref<VectorX> out) {
  model.measure_batch(states, inputs, out);
};

/// out(i) = h(points.col(i); inputs) for every column, in one batch call when the model has the
/// hook. `out` must already have points.cols() entries. No allocation for fixed sizes.
template <MeasurementModel M, typename Points, typename Out>
void evaluate_measurements(const M& model, const Eigen::MatrixBase<Points>& points,
                           const typename M::Inputs& inputs, Eigen::MatrixBase<Out>& out) {
  require_dimension("out", out.size(), points.cols());
  if constexpr (BatchMeasurementModel<M>) {
    model.measure_batch(points.derived(), inputs, Eigen::Ref<VectorX>(out.derived()));
  } else {
    constexpr int N = M::dimension_at_compile_time;
    Vector<N> state(points.rows());
    for (Index i = 0; i < points.cols(); ++i) {
      state = points.col(i);
      out(i) = model.measure(state, inputs);
    }
  }
}

}  // namespace twincal
