#pragma once
/// @file
/// `InformationProbe`: the probe that buys the most information per unit of expected quality
/// cost, among O(d) structured candidates (probe_design.hpp has the setting).
///
/// Candidates are the principal axes of S = H^{1/2} P H^{1/2} — the directions in which the
/// offset's uncertainty costs the most quality, tr(S) = tr(HP) being the expected excess of Q²
/// from miscalibration — mapped back to offsets, q_k = H^{+1/2} w_k (so q_kᵀ H q_k = 1), in both
/// signs and at amplitudes a on a geometric grid up to max_probe. For p = a q_k:
///   cost(p)  = pᵀ H p + 2 gᵀ p                     expected excess of Q² that p adds,
///   b        = −2 (g + H p)                         slope of the squared measurement in δu,
///   gain(p)  = bᵀ P H P b / (bᵀ P b + 2 tr(HPHP) + R(p))
///                                                   the drop of tr(HP) after the exact-moment
///                                                   update (quadratic_moments.hpp),
///   R(p)     = 4 E[Q²] σz² + 2 σz⁴                  variance of z² for z = Q + N(0, σz²),
/// and the design minimizes cost(p) − T·gain(p), including p = 0. The horizon T prices
/// information in assemblies of future quality, so the probe shrinks by itself when P is small
/// or the quality is insensitive (no tuned w: the trade-off of information-directed sampling,
/// Russo & Van Roy, Oper. Res. 66(1), 2018, with a myopic horizon). Both signs carry the same
/// information when g = 0; ties alternate the sign from one call to the next, so consecutive
/// probes do not bias the estimate in one direction.
///
/// Cost per call: two symmetric eigendecompositions and O(d³) products; the amplitude grid is
/// O(1) per point from scalars precomputed per axis. No allocation after the first call at a
/// size.

#include <algorithm>
#include <cmath>
#include <optional>
#include <string_view>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <nlohmann/json.hpp>

#include "twincal/controllers/controller_state_json.hpp"

#include "twincal/controllers/active/probe_design.hpp"
#include "twincal/core/eigen.hpp"

namespace twincal {

template <int N = Dynamic>
class InformationProbe {
 public:
  /// Amplitudes tried per axis and sign: the largest admissible one times ratio^k, k < count.
  static constexpr int amplitude_count = 48;
  static constexpr double amplitude_ratio = 0.8;

  void design(const ProbeContext<N>& context, Vector<N>& probe) {
    const SquareMatrix<N>& H = context.hessian;
    const SquareMatrix<N>& P = context.covariance;
    const Vector<N>& g = context.half_gradient;
    const Index d = P.rows();
    resize(d);
    probe.setZero(d);

    // H^{1/2} and H^{+1/2} from H = V Λ Vᵀ, Λ clipped at 0 (a fitted H may be semi-definite).
    hessian_eigen_->compute(H);
    const double largest = std::max(hessian_eigen_->eigenvalues().maxCoeff(), 0.0);
    if (!(largest > 0.0)) return;  // the quality ignores the offset: nothing to learn, no cost
    for (Index i = 0; i < d; ++i) {
      const double lambda = hessian_eigen_->eigenvalues()(i);
      const bool in_range = lambda > largest * 1e-12;
      root_(i) = in_range ? std::sqrt(lambda) : 0.0;
      inverse_root_(i) = in_range ? 1.0 / std::sqrt(lambda) : 0.0;
    }
    const SquareMatrix<N>& V = hessian_eigen_->eigenvectors();
    sqrt_h_.noalias() = V * root_.asDiagonal() * V.transpose();
    pinv_sqrt_h_.noalias() = V * inverse_root_.asDiagonal() * V.transpose();
    hp_.noalias() = P * sqrt_h_;
    s_.noalias() = sqrt_h_ * hp_;
    s_eigen_->compute(s_);

    hp_.noalias() = H * P;
    const double trace_hp = hp_.trace();
    const double trace_hphp = hp_.cwiseProduct(hp_.transpose()).sum();
    const double sigma2 = context.measurement_variance;
    // Slope at p = 0: b0 = −2g, and its quadratic forms with P and PHP.
    b0_ = -2.0 * g;
    pb0_.noalias() = P * b0_;
    const double b0_p_b0 = b0_.dot(pb0_);
    hpb_.noalias() = H * pb0_;
    const double b0_php_b0 = pb0_.dot(hpb_);
    const auto objective = [&](double cost, double bpb, double bphpb) {
      const double expected = context.value + cost + trace_hp;
      const double r = 4.0 * std::max(expected, 0.0) * sigma2 + 2.0 * sigma2 * sigma2;
      return cost - context.horizon * bphpb / (bpb + 2.0 * trace_hphp + r);
    };
    double best = objective(0.0, b0_p_b0, b0_php_b0);
    const double preferred_sign = flip_ ? -1.0 : 1.0;
    flip_ = !flip_;

    for (Index k = d - 1; k >= 0; --k) {  // largest uncertainty cost first
      q_.noalias() = pinv_sqrt_h_ * s_eigen_->eigenvectors().col(k);
      const double reach = q_.cwiseAbs().cwiseQuotient(context.max_probe).maxCoeff();
      if (!(reach > 0.0) || !std::isfinite(reach)) continue;
      // p = a q: b(a) = b0 + a b1 with b1 = −2 H q, cost(a) = a² qᵀHq + 2a gᵀq.
      b1_.noalias() = H * q_;
      const double q_h_q = q_.dot(b1_);
      b1_ *= -2.0;
      const double g_q = g.dot(q_);
      pb1_.noalias() = P * b1_;
      const double b0_p_b1 = b0_.dot(pb1_);
      const double b1_p_b1 = b1_.dot(pb1_);
      hpb_.noalias() = H * pb1_;
      const double b1_php_b1 = pb1_.dot(hpb_);
      const double b0_php_b1 = pb0_.dot(hpb_);
      const auto at = [&](double a) {
        const double cost = a * a * q_h_q + 2.0 * a * g_q;
        return objective(cost, b0_p_b0 + 2.0 * a * b0_p_b1 + a * a * b1_p_b1,
                         b0_php_b0 + 2.0 * a * b0_php_b1 + a * a * b1_php_b1);
      };
      double amplitude = 1.0 / reach;  // the largest a with |a q_i| <= max_probe_i
      for (int step = 0; step < amplitude_count; ++step, amplitude *= amplitude_ratio) {
        const double plus = at(amplitude);
        const double minus = at(-amplitude);
        const bool tie = std::abs(plus - minus) <= 1e-12 * std::max(std::abs(plus), 1e-300);
        const double sign = tie ? preferred_sign : (plus < minus ? 1.0 : -1.0);
        const double value = sign > 0.0 ? plus : minus;
        if (value < best) {
          best = value;
          probe.noalias() = (sign * amplitude) * q_;
        }
      }
    }
  }

  static constexpr std::string_view json_format = "twincal.information_probe";

  /// The sign the next tie takes: the design's only state (everything else is rewritten by every
  /// design()).
  [[nodiscard]] nlohmann::json save() const { return {{"format", json_format}, {"flip", flip_}}; }

  /// @throws InvalidArgumentError naming the field; the probe unchanged.
  void restore(const nlohmann::json& saved) {
    json_state::require_format(saved, json_format);
    flip_ = json_state::read_bool(saved, "flip");
  }

 private:
  void resize(Index d) {
    if (hessian_eigen_ && root_.size() == d) return;
    // Constructed in place: a default-constructed Eigen solver leaves its `info` uninitialized,
    // and copying or moving one reads it (UBSan), so the probe holds none until it is used.
    hessian_eigen_.emplace(d);
    s_eigen_.emplace(d);
    for (Vector<N>* v : {&root_, &inverse_root_, &b0_, &b1_, &pb0_, &pb1_, &hpb_, &q_}) {
      v->resize(d);
    }
    for (SquareMatrix<N>* m : {&sqrt_h_, &pinv_sqrt_h_, &s_, &hp_}) m->resize(d, d);
  }

  std::optional<Eigen::SelfAdjointEigenSolver<SquareMatrix<N>>> hessian_eigen_;
  std::optional<Eigen::SelfAdjointEigenSolver<SquareMatrix<N>>> s_eigen_;
  Vector<N> root_, inverse_root_, b0_, b1_, pb0_, pb1_, hpb_, q_;
  SquareMatrix<N> sqrt_h_, pinv_sqrt_h_, s_, hp_;
  bool flip_ = false;
};

}  // namespace twincal
