#pragma once
// Test support: small state and measurement models that make the filter's behaviour easy to
// provoke (counting, non-finite outputs, a linear measurement for near-singular updates).

#include <limits>

#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/evaluation_counter.hpp"
#include "twincal/filters/quadratic_quality_measurement.hpp"

namespace twincal::test_support {

/// h(x) = cᵀx with noise variance r.
template <int N>
struct LinearMeasurement {
  static constexpr int dimension_at_compile_time = N;
  struct Inputs {};
  Vector<N> c;
  double r;
  [[nodiscard]] double measure(const Vector<N>& x, const Inputs&) const { return c.dot(x); }
  [[nodiscard]] double noise_variance() const { return r; }
};

/// QuadraticQualityMeasurement that records every evaluation; with `batch` it also offers the
/// batch hook (recording one call of k points).
template <int N, bool batch>
struct CountingMeasurement {
  static constexpr int dimension_at_compile_time = N;
  using Inputs = typename QuadraticQualityMeasurement<N>::Inputs;
  QuadraticQualityMeasurement<N> model;
  EvaluationCounter* counter;

  [[nodiscard]] double measure(const Vector<N>& x, const Inputs& inputs) const {
    const auto scope = counter->scope(1);
    return model.measure(x, inputs);
  }
  void measure_batch(const Eigen::Ref<const MatrixX>& states, const Inputs& inputs,
                     Eigen::Ref<VectorX> out) const requires batch {
    const auto scope = counter->scope(static_cast<std::uint64_t>(states.cols()));
    model.measure_batch(states, inputs, out);
  }
  [[nodiscard]] double noise_variance() const { return model.noise_variance(); }
};

/// h = NaN wherever x(0) exceeds `threshold`, else x(0).
template <int N>
struct NanAboveThreshold {
  static constexpr int dimension_at_compile_time = N;
  struct Inputs {};
  double threshold;
  [[nodiscard]] double measure(const Vector<N>& x, const Inputs&) const {
    return x(0) > threshold ? std::numeric_limits<double>::quiet_NaN() : x(0);
  }
  [[nodiscard]] double noise_variance() const { return 1e-2; }
};

/// A state model whose f returns NaN.
template <int N>
struct ExplodingWalk {
  static constexpr int dimension_at_compile_time = N;
  SquareMatrix<N> q;
  [[nodiscard]] Index dimension() const { return q.rows(); }
  [[nodiscard]] Vector<N> propagate(const Vector<N>& x) const {
    return Vector<N>::Constant(x.size(), std::numeric_limits<double>::quiet_NaN());
  }
  [[nodiscard]] const SquareMatrix<N>& process_noise() const { return q; }
};

}  // namespace twincal::test_support
