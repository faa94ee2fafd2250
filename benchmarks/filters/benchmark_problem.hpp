#pragma once
// The problem every filter benchmark runs: a random walk (Q = 1e-3·I) observed through the
// analytic QuadraticQualityMeasurement (H = I), with fixed inputs.

#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/filters/quadratic_quality_measurement.hpp"

namespace twincal::benchmarks {

// The paper's random walk (eq. 5c), here to keep the benchmark within the filters module.
template <int N>
class Walk {
 public:
  static constexpr int dimension_at_compile_time = N;
  explicit Walk(Index n) : q_(SquareMatrix<N>::Identity(n, n) * 1e-3) {}
  [[nodiscard]] Index dimension() const { return q_.rows(); }
  [[nodiscard]] const Vector<N>& propagate(const Vector<N>& x) const { return x; }
  [[nodiscard]] const SquareMatrix<N>& process_noise() const { return q_; }

 private:
  SquareMatrix<N> q_;
};

template <int N>
QuadraticQualityMeasurement<N> measurement(Index n) {
  return QuadraticQualityMeasurement<N>(SquareMatrix<N>::Identity(n, n), 0.04, 1e-4);
}

template <int N>
typename QuadraticQualityMeasurement<N>::Inputs inputs(Index n) {
  return {Vector<N>::Constant(n, 0.05), Vector<N>::Constant(n, 0.1)};
}

}  // namespace twincal::benchmarks
