#pragma once
/// @file
/// `QuadraticQualityMeasurement<N>`: a cheap analytic measurement model with the shape of the
/// paper's quality feedback (eq. (5b), Assumption 1): the RMS-like quality of the control u
/// corrected by the offset state δu,
///
///   h(δu; a, u) = √(q0 + eᵀ H e),  e = u − δu − a,
///
/// with a the assembly's own deviation and H symmetric positive semi-definite. It is the
/// measurement of the reference filter runs (tests/data/filter_runs_*.json) and of the filter
/// benchmarks, and a stand-in for a twin while developing a controller.

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/fixed_size_dispatch.hpp"
#include "twincal/core/validate.hpp"
#include "twincal/filters/fixed_size_kernels.hpp"

namespace twincal {

template <int N>
class QuadraticQualityMeasurement {
 public:
  static constexpr int dimension_at_compile_time = N;

  /// The external inputs of one measurement: the assembly deviation a and the control u.
  struct Inputs {
    Vector<N> assembly;
    Vector<N> control;
  };

  /// @throws DimensionMismatchError, NonFiniteError, InvalidArgumentError (q0 < 0, R <= 0),
  ///         NotPositiveDefiniteError (H not positive semi-definite).
  QuadraticQualityMeasurement(const SquareMatrix<N>& weight, double offset, double noise_variance)
      : weight_(weight), offset_(offset), noise_variance_(noise_variance) {
    if constexpr (N != Dynamic) require_dimension("weight", weight_.rows(), N, "rows");
    require_positive_definite("weight", weight_, /*allow_semidefinite=*/true);
    require_finite("offset", offset_);
    require_non_negative("offset", offset_);
    require_finite("noise_variance", noise_variance_);
    require_positive("noise_variance", noise_variance_);
  }

  [[nodiscard]] Index dimension() const noexcept { return weight_.rows(); }
  [[nodiscard]] const SquareMatrix<N>& weight() const noexcept { return weight_; }
  [[nodiscard]] double offset() const noexcept { return offset_; }
  [[nodiscard]] double noise_variance() const noexcept { return noise_variance_; }

  /// h(δu; a, u). @throws DimensionMismatchError when a sizes differ from the dimension.
  [[nodiscard]] double measure(const Vector<N>& state, const Inputs& inputs) const {
    require_inputs(inputs);
    require_dimension("state", state.size(), dimension());
    return quality(inputs.control - inputs.assembly - state);
  }

  /// out(i) = h(states.col(i); a, u) for every column. Allocates nothing.
  void measure_batch(const Eigen::Ref<const MatrixX>& states, const Inputs& inputs,
                     Eigen::Ref<VectorX> out) const {
    require_inputs(inputs);
    require_dimension("states", states.rows(), dimension(), "rows");
    require_dimension("out", out.size(), states.cols());
    // Up to max_fixed_dispatch_size at compile-time size (fixed_size_kernels.hpp), which a
    // run-time size reaches through the compiled dispatch.
    if constexpr (N == Dynamic) {
      if (states.rows() <= max_fixed_dispatch_size) {
        StackVector shift = inputs.control - inputs.assembly;
        if (kernels::quadratic_qualities(weight_, offset_, shift, states, out)) return;
      }
    } else if constexpr (N <= max_fixed_dispatch_size) {
      const Vector<N> shift = inputs.control - inputs.assembly;
      kernels::quadratic_qualities<N>(weight_, offset_, shift, states.topRows<N>(), out);
      return;
    }
    for (Index i = 0; i < states.cols(); ++i) {
      out(i) = quality(inputs.control - inputs.assembly - states.col(i));
    }
  }

 private:
  // sqrt(q0 + eᵀHe) for an expression e, without touching the heap: e and He live in buffers
  // on the stack up to kStackDimension entries (one matrix-vector product, coefficient-based up
  // to lazy_product_max_rows, where Eigen's GEMV set-up would cost more than the product);
  // beyond that, e is read entry by entry (n dot products, slower but still allocation-free).
  static constexpr int kStackDimension = 64;
  using StackVector = Eigen::Matrix<double, N, 1, 0, (N == Dynamic ? kStackDimension : N), 1>;

  template <typename Error>
  [[nodiscard]] double quality(const Eigen::MatrixBase<Error>& e) const {
    double form = 0.0;
    if (N != Dynamic || e.size() <= kStackDimension) {
      const StackVector error = e;
      StackVector weighted(e.size());
      if constexpr (N == Dynamic) {
        if (e.size() <= lazy_product_max_rows) {
          weighted.noalias() = weight_.lazyProduct(error);
        } else {
          weighted.noalias() = weight_ * error;
        }
      } else {
        weighted.noalias() = weight_ * error;
      }
      form = error.dot(weighted);
    } else {
      for (Index c = 0; c < weight_.cols(); ++c) form += e(c) * weight_.col(c).dot(e);
    }
    // H is PSD, so eᵀHe >= 0 up to round-off; clamp that round-off away before the root.
    return std::sqrt(offset_ + std::max(form, 0.0));
  }

  void require_inputs(const Inputs& inputs) const {
    require_dimension("inputs.assembly", inputs.assembly.size(), dimension());
    require_dimension("inputs.control", inputs.control.size(), dimension());
  }

  SquareMatrix<N> weight_;
  double offset_;
  double noise_variance_;
};

}  // namespace twincal
