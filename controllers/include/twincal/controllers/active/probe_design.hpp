#pragma once
/// @file
/// `ProbeDesign`: how the active controller (active_controller.hpp) perturbs its control. The
/// control is u_t = u0(x_t) + δû_t + p_t with a known probe p_t: at p = 0 a quality measured at
/// its estimated optimum has no first-order dependence on the offset error (∂Q/∂δu = 0 there)
/// and cannot tell its sign; with p ≠ 0 the squared quality contains −2(g + H p)ᵀ(δu − δû), so
/// the error shows linearly. A design receives what it needs to weigh the probe's quality cost
/// against what it teaches the filter and writes p.
///
/// `ProbeContext<N>` (all in the squared-quality units of QuadraticModel):
/// - hessian H and half_gradient g of Q² at u0 (H = I and g = 0 for a twin that is not
///   quadratic: then only the offset covariance shapes the probe);
/// - covariance P of the offset estimate, after the time update;
/// - value c = Q²(u0) and measurement_variance σz² of z;
/// - horizon T: how many assemblies a unit of information keeps paying (the controller sets it);
/// - max_probe: the largest |p_i| per locator.

#include <concepts>
#include <string_view>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "twincal/controllers/controller_state_json.hpp"
#include "twincal/core/eigen.hpp"

namespace twincal {

template <int N>
struct ProbeContext {
  const SquareMatrix<N>& hessian;
  const Vector<N>& half_gradient;
  const SquareMatrix<N>& covariance;
  double value = 0.0;
  double measurement_variance = 0.0;
  double horizon = 1.0;
  const Vector<N>& max_probe;
};

template <typename D, int N>
concept ProbeDesign = requires(D& design, const ProbeContext<N>& context, Vector<N>& probe) {
  design.design(context, probe);
};

/// A design whose state between probes (a random stream, an alternating sign) can be saved and
/// restored, for the active controller's snapshot (SnapshotController, controller.hpp).
template <typename D>
concept SnapshotProbe = requires(const D& design, D& target, const nlohmann::json& saved) {
  { design.save() } -> std::same_as<nlohmann::json>;
  target.restore(saved);
};

/// p = 0: the default control u0 + δû (eq. 9) with the active controller's estimator — the
/// ablation that shows what probing buys.
template <int N = Dynamic>
struct NoProbe {
  void design(const ProbeContext<N>& context, Vector<N>& probe) const {
    probe.setZero(context.covariance.rows());
  }

  static constexpr std::string_view json_format = "twincal.no_probe";
  /// No state: the format alone.
  [[nodiscard]] nlohmann::json save() const { return {{"format", json_format}}; }
  /// @throws InvalidArgumentError for another format.
  void restore(const nlohmann::json& saved) const {
    json_state::require_format(saved, json_format);
  }
};

}  // namespace twincal
