#pragma once
/// @file
/// The `Controller` concept: one assembly at a time, `propose(x)` returns the control u_t to
/// apply to assembly x_t (eq. 5a, u_t = F(x_t; D_{t−1})), and `observe(x, u, z)` hands back the
/// quality z_t the plant measured, so the controller can learn from it (D_t = D_{t−1} ∪
/// {(x_t, u_t, z_t)}).
///
/// `EstimatingController` adds the filter's belief about the offset, eq. (8):
/// δu*_t ~ N(δû_t, P_t).
///
/// `SnapshotController` adds `save()` and `restore(saved)`: everything a controller carries from
/// one assembly to the next (filter, estimator, random streams, sampler positions, counters,
/// rings, the pending proposal and the last report) as JSON, so that `twincal serve` can resume
/// a long session from a snapshot instead of replaying its whole history. The contract: a
/// controller built with the same settings, twin and seeds, then restore(original.save()) —
/// also after the JSON went through text — behaves bit for bit like the original from then on.
/// restore() checks the saved `format` and dimensions and throws twincal's typed errors naming
/// the field, leaving the controller unchanged. A snapshot may be taken between any two calls,
/// also between a propose() and its observe() (the pending proposal is saved). Helpers:
/// controller_state_json.hpp.

#include <concepts>

#include <Eigen/Core>
#include <nlohmann/json_fwd.hpp>

#include "twincal/core/eigen.hpp"

namespace twincal {

template <typename C>
concept Controller = requires(C& controller, const typename C::Assembly& assembly,
                              const typename C::ControlVector& control, double z) {
  typename C::Assembly;
  typename C::ControlVector;
  { controller.propose(assembly) } -> std::convertible_to<typename C::ControlVector>;
  controller.observe(assembly, control, z);
};

template <typename C>
concept EstimatingController = Controller<C> && requires(const C& controller) {
  { controller.offset_estimate() } -> std::convertible_to<typename C::ControlVector>;
  { controller.offset_covariance() } -> std::convertible_to<MatrixX>;
};

template <typename C>
concept SnapshotController = Controller<C> &&
    requires(const C& controller, C& target, const nlohmann::json& saved) {
  { controller.save() } -> std::same_as<nlohmann::json>;
  target.restore(saved);
};

}  // namespace twincal
