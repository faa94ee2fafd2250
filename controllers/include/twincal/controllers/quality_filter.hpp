#pragma once
/// @file
/// `QualityFilter`: what the controllers need of a filter. Any filter of the filters module whose
/// measurement model is the paper's quality feedback (models' QualityFeedback: h(δu; x, u) =
/// Q(x, u − δu), eq. 5b) qualifies — SigmaPointFilter with any scheme (UKF, CKF, …) and
/// SquareRootSigmaPointFilter — with no code change in the controllers.
///
/// - predict(), state() (δû), covariance() (P), eq. (8);
/// - sigma_points() and mean_weights(): the points S_t and weights W of eq. (11);
/// - preview(values) → Preview with posterior_covariance P⁺(u) for given measurement values at
///   the sigma points, and commit(preview, z): the look-ahead of eq. (12) and the update share
///   one code path;
/// - measurement_model().measure_grid(x, U, S, out): Q(x, u_c − s_i) for every candidate control
///   and sigma point in one twin batch call.

#include <concepts>
#include <cstdint>
#include <type_traits>

#include <Eigen/Core>
#include <nlohmann/json_fwd.hpp>

#include "twincal/core/eigen.hpp"

namespace twincal {

template <typename F>
using MeasurementModelOf =
    std::remove_cvref_t<decltype(std::declval<const F&>().measurement_model())>;

template <typename F>
concept QualityFilter = requires(F& filter, const F& const_filter, double z,
                                 const typename F::Preview& preview, const VectorX& values,
                                 const typename F::Inputs& inputs) {
  typename F::StateVector;
  typename F::CovarianceMatrix;
  typename F::Preview;
  typename F::Inputs;
  { F::dimension_at_compile_time } -> std::convertible_to<int>;
  filter.predict();
  { const_filter.dimension() } -> std::convertible_to<Index>;
  { const_filter.state() } -> std::convertible_to<typename F::StateVector>;
  { const_filter.covariance() } -> std::convertible_to<typename F::CovarianceMatrix>;
  { const_filter.sigma_points() } -> std::convertible_to<MatrixX>;
  { const_filter.mean_weights() } -> std::convertible_to<VectorX>;
  { const_filter.preview(values) } -> std::same_as<typename F::Preview>;
  { preview.posterior_covariance } -> std::convertible_to<typename F::CovarianceMatrix>;
  filter.commit(preview, z);
  filter.update(z, inputs);
  typename MeasurementModelOf<F>::Assembly;
  {const_filter.measurement_model().twin()};
}
&&requires(const MeasurementModelOf<F>& model,
           const typename MeasurementModelOf<F>::Assembly& assembly,
           const Eigen::Ref<const MatrixX>& controls, const Eigen::Ref<const MatrixX>& states,
           Eigen::Ref<MatrixX> out) {
  model.measure_grid(assembly, controls, states, out);
};

/// A QualityFilter whose state can be saved and restored (SigmaPointFilter,
/// SquareRootSigmaPointFilter: save() and restore(saved), bit-exact), as a controller's snapshot
/// needs (SnapshotController, controller.hpp). restore() changes revision(), so a controller that
/// restores a pending preview stamps it with the new one.
template <typename F>
concept SnapshotFilter = QualityFilter<F> &&
    requires(const F& filter, F& target, const nlohmann::json& saved) {
  { filter.save() } -> std::same_as<nlohmann::json>;
  target.restore(saved);
  { filter.revision() } -> std::convertible_to<std::uint64_t>;
};

}  // namespace twincal
