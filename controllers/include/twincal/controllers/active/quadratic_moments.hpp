#pragma once
/// @file
/// Exact Gaussian moments of the squared-quality measurement under a quadratic model: for
/// δu ~ N(m, P) and h(δu) = Q²(x, u − δu) with Q² the QuadraticModel (c, g, H) around v0,
/// write e = u − m − v0 and ε = δu − m, so that
///   h = Q²(u − m) − 2 (g + H e)ᵀ ε + εᵀ H ε,
/// and, ε being N(0, P),
///   E[h]        = Q²(u − m) + tr(H P),
///   Cov(δu, h)  = −2 P (g + H e),
///   Var(h)      = 4 (g + H e)ᵀ P (g + H e) + 2 tr(H P H P).
/// These are the second-order EKF's moments, exact for a quadratic measurement (Gustafsson &
/// Hendeby, IEEE TSP 60(2), 2012): the Kalman update built on them is the linear MMSE update,
/// with no sigma points and no linearization error. The εᵀHε term that a scalar quality at the
/// optimum is made of enters as the 2 tr(HPHP) of the variance: it carries no first-order
/// information, which is why the active controller probes (active_controller.hpp).

#include <Eigen/Core>

#include "twincal/controllers/active/quadratic_model.hpp"
#include "twincal/core/eigen.hpp"

namespace twincal {

template <int N>
struct QuadraticMeasurementMoments {
  double mean = 0.0;           ///< E[h]
  Vector<N> cross_covariance;  ///< Cov(δu, h)
  double variance = 0.0;       ///< Var(h)
};

/// Workspace for quadratic_measurement_moments: sized once, so repeated calls at a dynamic size
/// allocate nothing.
template <int N>
struct QuadraticMomentsWorkspace {
  Vector<N> deviation;
  Vector<N> slope;
  SquareMatrix<N> hp;

  void resize(Index d) {
    deviation.resize(d);
    slope.resize(d);
    hp.resize(d, d);
  }
};

/// Moments of h(δu) = Q²(x, u − δu) for δu ~ N(mean, covariance); `out.cross_covariance` must
/// have the model's size.
template <int N>
void quadratic_measurement_moments(const QuadraticModel<N>& model, const Vector<N>& control,
                                   const Vector<N>& mean, const SquareMatrix<N>& covariance,
                                   QuadraticMomentsWorkspace<N>& work,
                                   QuadraticMeasurementMoments<N>& out) {
  work.deviation = control - mean;  // u − m, the control the twin sees at the mean
  const double at_mean = model(work.deviation);
  work.deviation -= model.center;  // e
  work.slope = model.half_gradient;
  work.slope.noalias() += model.hessian * work.deviation;  // g + H e
  work.hp.noalias() = model.hessian * covariance;
  const double trace_hp = work.hp.trace();
  // tr(HPHP) = Σ_jk (HP)_jk (HP)_kj.
  const double trace_hphp = work.hp.cwiseProduct(work.hp.transpose()).sum();
  out.mean = at_mean + trace_hp;
  out.cross_covariance.noalias() = covariance * work.slope;
  out.variance = 4.0 * work.slope.dot(out.cross_covariance) + 2.0 * trace_hphp;
  out.cross_covariance *= -2.0;
}

}  // namespace twincal
