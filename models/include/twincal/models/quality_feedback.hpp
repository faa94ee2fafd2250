#pragma once
/// @file
/// `QualityFeedback<T, N>`: the paper's measurement model, eq. (5b) under Assumption 1 (eq. 4):
///   h(δu; x, u) = Q(x, u − δu; θ0),   Z = h(δu*; x, u) + v,   v ~ N(0, σz²).
/// The state is the locator offset δu (N entries, N may be Dynamic); the inputs given at update
/// time are the assembly x and the applied control u.
///
/// It satisfies the filters' MeasurementModel shape structurally (models depends on core only):
/// `Inputs`, `dimension_at_compile_time`, `measure`, `noise_variance` and the batch hook
/// `measure_batch`, which evaluates all sigma points with ONE call of the twin's batch interface.
/// `measure_grid` serves look-ahead controllers: Q(x, u_c − s_i) for C candidate controls and M
/// sigma points, again in one twin batch call.
///
/// The batch forms shift the controls into a per-thread, grow-only workspace, so repeated calls
/// of the same size do not allocate (fixed or dynamic N) and concurrent calls from different
/// threads do not share memory. The model refers to the twin, which must outlive it; wrap the
/// twin in an Evaluator to count, time, check and parallelize the evaluations.

#include <algorithm>
#include <cmath>

#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/validate.hpp"
#include "twincal/models/kept_assemblies.hpp"
#include "twincal/models/twin.hpp"

namespace twincal {

template <Twin T, int N = Dynamic>
class QualityFeedback {
 public:
  static constexpr int dimension_at_compile_time = N;
  using TwinType = T;
  using Assembly = typename T::Assembly;
  static constexpr bool borrows_assemblies = borrows_assemblies_v<T>;
  using StateVector = Vector<N>;

  /// The external inputs of eq. (5b): the assembly x_t and the applied control u_t.
  struct Inputs {
    Assembly assembly;
    StateVector control;
  };

  /// h with noise variance R = σz² (> 0, finite).
  /// @throws DimensionMismatchError when N is fixed and differs from the twin's d;
  ///         NonFiniteError / InvalidArgumentError for a bad `noise_variance`.
  QualityFeedback(const T& twin, double noise_variance)
      : twin_(&twin), noise_variance_(noise_variance) {
    if constexpr (N != Dynamic) {
      require_dimension("twin.control_dimension()", twin.control_dimension(), N);
    }
    require_finite("noise_variance", noise_variance);
    require_positive("noise_variance", noise_variance);
  }

  [[nodiscard]] Index dimension() const noexcept { return twin_->control_dimension(); }
  [[nodiscard]] const T& twin() const noexcept { return *twin_; }

  /// R = σz².
  [[nodiscard]] double noise_variance() const noexcept { return noise_variance_; }

  /// h(δu; x, u) = Q(x, u − δu).
  /// @throws DimensionMismatchError naming "state" or "inputs.control"; whatever the twin throws.
  [[nodiscard]] double measure(const StateVector& state, const Inputs& inputs) const {
    check_inputs(inputs);
    require_dimension("state", state.size(), dimension());
    if constexpr (N != Dynamic) {
      const StateVector shifted = inputs.control - state;
      return twin_->quality(inputs.assembly, shifted);
    } else {
      ControlsBlock shifted = controls_workspace(dimension(), 1);
      shifted.col(0) = inputs.control - state;
      return twin_->quality(inputs.assembly, shifted.col(0));
    }
  }

  /// out(j) = h(states.col(j); x, u) for the N × k `states` (one sigma point per column), with
  /// one call of the twin's `quality_batch`.
  void measure_batch(const Eigen::Ref<const MatrixX>& states, const Inputs& inputs,
                     Eigen::Ref<VectorX> out) const {
    check_inputs(inputs);
    require_dimension("states", states.rows(), dimension(), "rows");
    require_dimension("out", out.size(), states.cols());
    ControlsBlock shifted = controls_workspace(dimension(), states.cols());
    shifted = (-states).colwise() + inputs.control;
    twin_->quality_batch(inputs.assembly, shifted, out);
  }

  /// out(i, c) = Q(x, controls.col(c) − states.col(i)) for the d × C candidate `controls` and the
  /// d × M `states` (out is M × C), with one call of the twin's `quality_batch` over all C·M
  /// pairs (candidate-major). Column c of `out` is what measure_batch would give for the inputs
  /// {assembly, controls.col(c)}.
  void measure_grid(const Assembly& assembly, const Eigen::Ref<const MatrixX>& controls,
                    const Eigen::Ref<const MatrixX>& states, Eigen::Ref<MatrixX> out) const {
    const Index d = dimension();
    require_dimension("controls", controls.rows(), d, "rows");
    require_dimension("states", states.rows(), d, "rows");
    require_shape("out", out, states.cols(), controls.cols());
    const Index m = states.cols();
    const Index pairs = m * controls.cols();
    ControlsBlock shifted = controls_workspace(d, pairs);
    for (Index c = 0; c < controls.cols(); ++c) {
      shifted.middleCols(c * m, m) = (-states).colwise() + controls.col(c);
    }
    Eigen::VectorBlock<VectorX> values = values_workspace(pairs);
    twin_->quality_batch(assembly, shifted, values);
    out = values.reshaped(m, controls.cols());
  }

 private:
  using ControlsBlock = Eigen::Block<MatrixX, Dynamic, Dynamic, true>;

  void check_inputs(const Inputs& inputs) const {
    require_dimension("inputs.control", inputs.control.size(), dimension());
  }

  // Per-thread buffers that only grow: a batch of a size seen before reuses the memory.
  static ControlsBlock controls_workspace(Index rows, Index cols) {
    thread_local MatrixX buffer;
    if (buffer.rows() != rows || buffer.cols() < cols) {
      buffer.resize(rows, std::max(cols, buffer.rows() == rows ? buffer.cols() : Index{0}));
    }
    return buffer.leftCols(cols);
  }
  static Eigen::VectorBlock<VectorX> values_workspace(Index size) {
    thread_local VectorX buffer;
    if (buffer.size() < size) buffer.resize(size);
    return buffer.head(size);
  }

  const T* twin_;
  double noise_variance_;
};

}  // namespace twincal
