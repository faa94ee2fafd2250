#pragma once
/// @file
/// The `Controller` concept: one assembly at a time, `propose(x)` returns the control u_t to
/// apply to assembly x_t (eq. 5a, u_t = F(x_t; D_{t−1})), and `observe(x, u, z)` hands back the
/// quality z_t the plant measured, so the controller can learn from it (D_t = D_{t−1} ∪
/// {(x_t, u_t, z_t)}).
///
/// `EstimatingController` adds the filter's belief about the offset, eq. (8):
/// δu*_t ~ N(δû_t, P_t).

#include <concepts>

#include <Eigen/Core>

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

}  // namespace twincal
