#pragma once
/// @file
/// `ConstantVelocityEstimator<N>`: a moving-horizon estimate of a drifting offset δu from the
/// assemblies measured so far, for the active controller (active_controller.hpp).
///
/// Model. Over the history the offset moves with a constant velocity,
///   δu_k = a + (k − t) b,
/// a the offset at the assembly t being estimated and b its velocity per assembly (the paper's
/// drift, eq. (15), is piecewise of this form). Assembly k was measured at control u_k with the
/// twin's local model Q²(x_k, v) ≈ c_k + 2 g_kᵀ(v − u0_k) + (v − u0_k)ᵀ H_k (v − u0_k)
/// (quadratic_model.hpp); the plant measures z_k = Q(x_k, u_k − δu_k) + N(0, σz²) (eq. 5b), so
///   z_k ≈ m_k(a, b) = sqrt(c_k + 2 g_kᵀ r_k + r_kᵀ H_k r_k),   r_k = u_k − u0_k − δu_k.
/// Each assembly's residual z_k − m_k has variance σz² + τ_k², τ_k² the variance of its model's
/// own error (0 for a twin whose Q² is a quadratic; see add()), so an assembly whose model
/// explains the twin badly weighs less.
/// The estimate is the maximum a posteriori (a, b) under a Gaussian prior, found by Gauss–Newton
/// with step halving, and its covariance the inverse of the Gauss–Newton matrix there (Laplace).
/// Unlike a random-walk filter, it follows a drift without lag: with consistent data the estimate
/// converges to the drift as the data outweigh the prior, whatever σz² is assumed.
///
/// Change of velocity. When the last `change_window` residuals under the fit are beyond
/// `change_gate` (root mean square, normalized by σz), the velocity has changed: the fit
/// restarts from the estimate it made `change_lag` assemblies ago (the change could not bias it
/// then), with a prior that widens the offset and the velocity along the old velocity's line,
/// and keeps only the assemblies measured since.
///
/// Misfit. Residuals larger than σz² + τ_k² explains (a twin whose models err more than their
/// checks say) are measured by the median normalized innovation of the last assemblies, and the
/// change gate and the significance test are taken in those units (ConstantVelocityOptions::
/// misfit_window).
///
/// Relinearization. A model fitted where the estimate put an assembly is used, after later
/// fits, where they put it; the owner can refit it there (entry_point(), relinearize()), which
/// makes the fit Gauss–Newton on the twin itself rather than on the first models.
///
/// Local minima. A scalar quality is symmetric in the error r_k: a fit warm-started from the last
/// estimate that explains the data badly is also started from its mirror image and from the
/// prior mean, and the best of the three is kept.
///
/// Cost per fit: O(n (2d)²) per iteration for n assemblies in the history, plus O(d³) solves;
/// no allocation after construction (the history is a ring of `max_history` assemblies).

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <string_view>
#include <vector>

#include <fmt/format.h>
#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <nlohmann/json.hpp>

#include "twincal/controllers/constant_velocity_options.hpp"
#include "twincal/controllers/controller_state_json.hpp"
#include "twincal/controllers/quadratic_model.hpp"
#include "twincal/core/eigen.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/options.hpp"
#include "twincal/core/symmetrize.hpp"
#include "twincal/core/validate.hpp"

namespace twincal {

template <int N = Dynamic>
class ConstantVelocityEstimator {
 public:
  static constexpr int state_size = N == Dynamic ? Dynamic : 2 * N;
  using OffsetVector = Vector<N>;
  using OffsetMatrix = SquareMatrix<N>;
  using StateVector = Vector<state_size>;
  using StateMatrix = SquareMatrix<state_size>;

  /// An estimator for offsets in a box of widths `box_width` (entries > 0), measured with
  /// variance `measurement_variance` (σz² of z). Call reset() before the first fit.
  /// @throws InvalidArgumentError (options, widths, variance), DimensionMismatchError.
  ConstantVelocityEstimator(const VectorX& box_width, double measurement_variance,
                            const ConstantVelocityOptions& options = {});

  [[nodiscard]] Index dimension() const noexcept { return width_.size(); }
  [[nodiscard]] const ConstantVelocityOptions& options() const noexcept { return options_; }
  /// Assemblies in the history.
  [[nodiscard]] Index history_size() const noexcept { return size_; }
  /// Changes of velocity declared so far, and whether the last fit declared one.
  [[nodiscard]] Index changes() const noexcept { return changes_; }
  [[nodiscard]] bool changed() const noexcept { return changed_; }
  /// Whether the history shows an offset: the fit explains it better than δu = 0 by more than
  /// chance would (see ConstantVelocityOptions::significance).
  [[nodiscard]] bool significant() const noexcept { return significant_; }
  /// The assembly the last fit estimated, and its (a, b) and covariance.
  [[nodiscard]] Index fit_time() const noexcept { return fit_time_; }
  [[nodiscard]] const StateVector& state() const noexcept { return state_; }
  [[nodiscard]] const StateMatrix& covariance() const noexcept { return covariance_; }
  /// a, the offset at fit_time(), and its covariance.
  [[nodiscard]] const OffsetVector& position() const noexcept { return position_; }
  [[nodiscard]] const OffsetMatrix& position_covariance() const noexcept {
    return position_covariance_;
  }

  /// Forgets the history and starts from δu ~ N(position, position_covariance) at `time`, with
  /// a velocity ~ N(0, (velocity_fraction · width)²) per locator.
  /// @throws DimensionMismatchError, NonFiniteError, NotPositiveDefiniteError; state unchanged.
  void reset(Index time, const OffsetVector& position, const OffsetMatrix& position_covariance);

  /// reset() with δu ~ N(position, (initial_position_fraction · width)²) per locator: the start
  /// of an episode.
  void reset(Index time, const OffsetVector& position) {
    const Index d = dimension();
    OffsetMatrix covariance = OffsetMatrix::Zero(d, d);
    covariance.diagonal() = (options_.initial_position_fraction * width_).array().square().matrix();
    reset(time, position, covariance);
  }

  /// Adds assembly `time` (≥ every time in the history), measured at `control` with quality z
  /// under `model`, whose error as a model of the twin's Q has variance `model_variance`
  /// (added to σz²), to the history. Returns the normalized innovation ν²/S of z against the
  /// estimate at `time` before it (fitted first if it is not the last fit).
  /// @throws DimensionMismatchError, NonFiniteError, InvalidArgumentError (time, a negative
  ///         model_variance); state unchanged.
  double add(Index time, const QuadraticModel<N>& model, const OffsetVector& control, double z,
             double model_variance = 0.0);

  /// The estimate at assembly `time` from the prior and the history (see the file comment).
  void fit(Index time);

  /// s², the misfit of the history's entries whose model errs, in units of their residuals'
  /// variance σz² + τ² (>= 1; ConstantVelocityOptions::misfit_window): the unit of the change
  /// gate and the significance test.
  [[nodiscard]] double misfit_scale() const noexcept { return model_misfit_.scale(); }
  /// How badly the estimator predicts the plant: the median normalized innovation ν²/S of the
  /// last misfit_window assemblies, every entry (S = σz² + τ² + the estimate's variance along
  /// the model's slope), over χ²(1)'s median, at least 1; 1 until half the window is in. Unlike
  /// misfit_scale() it counts exact models too, so a plant that is not the twin shows here.
  /// Each innovation is predicted before its entry joins the fit, so, unlike the fit's own
  /// residuals (which 2d unknowns absorb until the history holds well over 2d entries), it
  /// speaks at any d.
  [[nodiscard]] double prediction_scale() const noexcept { return prediction_misfit_.scale(); }

  /// The time of history entry i (0 the oldest).
  [[nodiscard]] Index entry_time(Index i) const noexcept { return time_of(i); }

  /// Where entry i was measured in the twin's frame under the last fit, u_i − δu_i (δu_i = a +
  /// (t_i − t) b), and how far that lies from its model's centre, in `offset`.
  void entry_point(Index i, OffsetVector& point, OffsetVector& offset) const {
    const Index d = dimension();
    const Index s = slot(i);
    const double tau = static_cast<double>(times_[static_cast<std::size_t>(s)] - fit_time_);
    point = applied_.col(s) - state_.head(d) - tau * state_.tail(d);
    offset = controls_.col(s) - state_.head(d) - tau * state_.tail(d);
  }

  /// τ² of entry i: its residual's variance beyond σz².
  [[nodiscard]] double entry_model_variance(Index i) const noexcept {
    return model_variances_(slot(i));
  }

  /// The Hessian entry i's model uses (as fitted, negative eigenvalues clipped at 0).
  [[nodiscard]] auto entry_hessian(Index i) const {
    const Index d = dimension();
    return hessians_.middleCols(slot(i) * d, d);
  }

  /// Replaces entry i's model by `model` (refitted for the same assembly, e.g. at entry_point):
  /// the measurement stays; its residual variance becomes σz² + model_variance. The estimate
  /// changes at the next fit().
  /// @throws DimensionMismatchError, NonFiniteError, InvalidArgumentError (i, model_variance);
  ///         state unchanged.
  void relinearize(Index i, const QuadraticModel<N>& model, double model_variance);

  static constexpr std::string_view json_format = "twincal.constant_velocity_estimator";

  /// Everything a later add(), fit() or relinearize() reads: the history (each entry at its ring
  /// slot, so that every later sum runs over the same memory in the same order; an entry's H
  /// written once for a run of equal ones), the last H added as fitted, the estimates of the
  /// last change_lag + 1 fits, the prior, the estimate with its flags and counters, and the
  /// misfit scales with their ring. Not the workspaces of a fit (Gauss–Newton buffers, shifted
  /// prior, factorizations), which every fit rewrites before reading them, nor the weights
  /// 1/(σz² + τ²), recomputed from τ².
  [[nodiscard]] nlohmann::json save() const;

  /// Restores a snapshot of save() into an estimator of the same box, σz² and options.
  /// @throws InvalidArgumentError, DimensionMismatchError, NonFiniteError naming the field
  ///         ("history[3].quality"); the estimator unchanged.
  void restore(const nlohmann::json& saved);

 private:
  // Stores `hessian`, its negative eigenvalues clipped at 0, in ring slot i.
  void clip_hessian(const OffsetMatrix& hessian, Index i) {
    const Index d = dimension();
    hessian_eigen_.compute(hessian);
    if (hessian_eigen_.eigenvalues().minCoeff() < 0.0) {
      hessians_.middleCols(i * d, d).noalias() =
          hessian_eigen_.eigenvectors() * hessian_eigen_.eigenvalues().cwiseMax(0.0).asDiagonal() *
          hessian_eigen_.eigenvectors().transpose();
    } else {
      hessians_.middleCols(i * d, d) = hessian;
    }
  }

  [[nodiscard]] Index slot(Index i) const noexcept { return (head_ + i) % options_.max_history; }
  [[nodiscard]] Index time_of(Index i) const noexcept {
    return times_[static_cast<std::size_t>(slot(i))];
  }

  // The prior moved from prior_time_ to `time` along the constant velocity: θ_t = M θ_p with
  // M = [I, Δ I; 0, I], Σ_t = M Σ_p Mᵀ, and its precision.
  void shift_prior(Index time) {
    const Index d = dimension();
    const double delta = static_cast<double>(time - prior_time_);
    shift_.topRightCorner(d, d).diagonal().setConstant(delta);
    shifted_mean_.noalias() = shift_ * prior_mean_;
    normal_.noalias() = shift_ * prior_covariance_;
    shifted_covariance_.noalias() = normal_ * shift_.transpose();
    symmetrize(shifted_covariance_);
    cap_prior();
    factor_.compute(shifted_covariance_);
    prior_precision_ = factor_.solve(identity_);
    symmetrize(prior_precision_);
  }

  // The prior never claims more uncertainty than the start's: in units of the start's standard
  // deviations (position_fraction · width, velocity_fraction · width) its eigenvalues are capped
  // at 1. Without the cap, directions the quality barely sees (a door's H has rank ≈ 3) would
  // let the velocity's uncertainty grow the offset's without bound, and the probes with it.
  void cap_prior() {
    const Index d = dimension();
    prior_scale_.head(d) = options_.position_fraction * width_;
    prior_scale_.tail(d) = options_.velocity_fraction * width_;
    const bool beyond =
        (shifted_covariance_.diagonal().array() > prior_scale_.array().square()).any();
    if (!beyond) return;
    normal_ = prior_scale_.cwiseInverse().asDiagonal() * shifted_covariance_ *
              prior_scale_.cwiseInverse().asDiagonal();
    state_eigen_.compute(normal_);
    normal_.noalias() = state_eigen_.eigenvectors() *
                        state_eigen_.eigenvalues().cwiseMin(1.0).asDiagonal() *
                        state_eigen_.eigenvectors().transpose();
    shifted_covariance_ = prior_scale_.asDiagonal() * normal_ * prior_scale_.asDiagonal();
  }

  // z − m for history entry i (r = v − a − τ b); writes slope_ = ∂m/∂a. A non-positive model
  // value (a fitted H may be indefinite) is clamped, with a zero slope.
  double residual_at(Index i, const StateVector& state, Index time) {
    const Index d = dimension();
    const Index s = slot(i);
    const double tau = static_cast<double>(times_[static_cast<std::size_t>(s)] - time);
    error_ = controls_.col(s) - state.head(d) - tau * state.tail(d);
    curvature_error_.noalias() = hessians_.middleCols(s * d, d) * error_;
    const double squared =
        values_(s) + 2.0 * half_gradients_.col(s).dot(error_) + error_.dot(curvature_error_);
    const double floor = 1e-12 * (1.0 + std::abs(values_(s)));
    if (squared > floor) {
      const double model = std::sqrt(squared);
      slope_ = -(half_gradients_.col(s) + curvature_error_) / model;
      return qualities_(s) - model;
    }
    slope_.setZero();
    return qualities_(s) - std::sqrt(floor);
  }

  // Normalized residuals e_k/σ_k and their Jacobian of the history at `state`; returns the data
  // cost Σ e_k²/σ_k², σ_k² = σz² + τ_k².
  double evaluate(const StateVector& state, Index time, bool jacobian) {
    const Index d = dimension();
    double cost = 0.0;
    for (Index i = 0; i < size_; ++i) {
      const double scale = std::sqrt(weights_(slot(i)));
      const double e = scale * residual_at(i, state, time);
      residuals_(i) = e;
      cost += e * e;
      if (jacobian) {
        const double tau = static_cast<double>(time_of(i) - time);
        jacobian_.row(i).head(d) = scale * slope_.transpose();
        jacobian_.row(i).tail(d) = (scale * tau) * slope_.transpose();
      }
    }
    return cost;
  }

  // Gauss–Newton with step halving from `start`; writes the minimizer to `out` and returns the
  // total cost (data_cost_ keeps its data part). The Gauss–Newton matrix at the estimate is
  // formed once, by finish().
  double solve(const StateVector& start, Index time, StateVector& out) {
    out = start;
    double data = evaluate(out, time, true);
    double cost = data + prior_cost(out);
    for (int iteration = 0; iteration < options_.max_iterations; ++iteration) {
      assemble(out);
      step_ = factor_.solve(gradient_);
      double scale = 1.0;
      bool improved = false;
      for (int halving = 0; halving < 10 && !improved; ++halving) {
        if (halving > 0) scale *= 0.5;
        trial_ = out + scale * step_;
        const double trial_data = evaluate(trial_, time, false);
        const double trial_cost = trial_data + prior_cost(trial_);
        if (trial_cost <= cost) {
          improved = true;
          data = trial_data;
          cost = trial_cost;
        }
      }
      if (!improved) break;
      out = trial_;
      if (scale * step_.norm() <= options_.step_tolerance * (1.0 + out.norm())) break;
      if (iteration + 1 < options_.max_iterations) evaluate(out, time, true);  // for assemble()
    }
    data_cost_ = data;
    return cost;
  }

  double prior_cost(const StateVector& state) {
    difference_ = state - shifted_mean_;
    weighted_difference_.noalias() = prior_precision_ * difference_;
    return difference_.dot(weighted_difference_);
  }

  // normal_ = JᵀJ + Λ, gradient_ = Jᵀe − Λ(θ − μ) (J and e normalized by σ_k), factored; needs
  // evaluate(·, true).
  void assemble(const StateVector& state) {
    const Index n = size_;
    normal_ = prior_precision_;
    normal_.noalias() += jacobian_.topRows(n).transpose() * jacobian_.topRows(n);
    prior_cost(state);
    gradient_ = -weighted_difference_;
    gradient_.noalias() += jacobian_.topRows(n).transpose() * residuals_.head(n);
    factor_.compute(normal_);
  }

  // The root-mean-square normalized residual of the last change_window assemblies beyond the
  // gate.
  bool recent_misfit(const StateVector& state, Index time) {
    const Index window = options_.change_window;
    double sum = 0.0;
    for (Index i = size_ - window; i < size_; ++i) {
      const double e = residual_at(i, state, time);
      sum += weights_(slot(i)) * e * e;
    }
    const double mean = sum / static_cast<double>(window);
    return mean > options_.change_gate * options_.change_gate * model_misfit_.scale();
  }

  // A change of velocity: the prior becomes the estimate of change_lag fits ago, widened along
  // its velocity's line, and the history keeps the assemblies measured since.
  void restart_at_change(Index time) {
    const Index d = dimension();
    const Index lags = options_.change_lag + 1;
    // The oldest snapshot kept is change_lag fits ago (or the first, early on).
    const Index oldest = snapshots_ < lags ? 0 : snapshots_ % lags;
    const Index restart_time = snapshot_times_[static_cast<std::size_t>(oldest)];
    velocity_ = snapshot_states_.col(oldest).tail(d);
    prior_mean_.head(d) = snapshot_states_.col(oldest).head(d);
    prior_mean_.tail(d).setZero();
    prior_covariance_.setZero();
    prior_covariance_.topLeftCorner(d, d) =
        snapshot_covariances_.middleCols(oldest * d, d) +
        options_.change_position_spread * velocity_ * velocity_.transpose();
    prior_covariance_.bottomRightCorner(d, d) =
        options_.change_velocity_spread * velocity_ * velocity_.transpose();
    prior_covariance_.diagonal().tail(d) +=
        (options_.change_velocity_floor_fraction * width_).array().square().matrix();
    prior_time_ = restart_time;
    while (size_ > 0 && time_of(0) < restart_time) {
      head_ = (head_ + 1) % options_.max_history;
      --size_;
    }
    shift_prior(time);
  }

  // The covariance (the inverse Gauss–Newton matrix at state_), the position and a snapshot.
  void finish(Index time) {
    const Index d = dimension();
    // Significance: the fit against "no offset", Δ = cost(0) − cost(θ̂) over the history, which
    // is χ² with 2d degrees of freedom when there is none; beyond its mean + k·sd it is real.
    trial_.setZero();
    const double no_offset = evaluate(trial_, time, false);
    const double fitted = evaluate(state_, time, true);  // and the Gauss–Newton matrix there
    const double dof = static_cast<double>(2 * d);
    significant_ = (no_offset - fitted) / model_misfit_.scale() >
                   dof + options_.significance * std::sqrt(2.0 * dof);
    assemble(state_);
    covariance_ = factor_.solve(identity_);
    symmetrize(covariance_);
    position_ = state_.head(d);
    position_covariance_ = covariance_.topLeftCorner(d, d);
    fit_time_ = time;
    fitted_ = true;
    const Index lags = options_.change_lag + 1;
    const Index i = snapshots_ % lags;
    snapshot_times_[static_cast<std::size_t>(i)] = time;
    snapshot_states_.col(i) = state_;
    snapshot_covariances_.middleCols(i * d, d) = position_covariance_;
    ++snapshots_;
  }

  ConstantVelocityOptions options_;
  double measurement_variance_;
  VectorX width_;
  // The history, a ring of max_history assemblies starting at head_.
  std::vector<Index> times_;
  Matrix<N, Dynamic> controls_;  // u_k − v_k, v_k the centre of entry k's model
  Matrix<N, Dynamic> applied_;   // u_k
  VectorX values_;
  Matrix<N, Dynamic> half_gradients_;
  Matrix<N, Dynamic> hessians_;  // d × d blocks side by side
  VectorX qualities_;
  VectorX weights_;          // 1/(σz² + τ_k²)
  VectorX model_variances_;  // τ_k²
  Index head_ = 0;
  Index size_ = 0;
  // The estimates of the last change_lag + 1 fits.
  std::vector<Index> snapshot_times_;
  Matrix<state_size, Dynamic> snapshot_states_;
  Matrix<N, Dynamic> snapshot_covariances_;
  Index snapshots_ = 0;
  // The prior, at prior_time_.
  StateVector prior_mean_;
  StateMatrix prior_covariance_;
  Index prior_time_ = 0;
  // The estimate.
  StateVector state_;
  StateMatrix covariance_;
  OffsetVector position_;
  OffsetMatrix position_covariance_;
  Index fit_time_ = 0;
  bool fitted_ = false;
  Index changes_ = 0;
  bool changed_ = false;
  bool significant_ = false;
  double data_cost_ = 0.0;
  // The median of the last n normalized innovations ν²/S over χ²(1)'s median (0.4549), at least
  // 1 — not before half of n are in: the first innovations also carry the start's error (a
  // start far from the offset would otherwise gate off the changes that recover from it).
  class MedianMisfit {
   public:
    void resize(Index n) {
      ring_.assign(static_cast<std::size_t>(n), 0.0);
      sorted_.assign(ring_.size(), 0.0);
    }
    void clear() noexcept {
      count_ = 0;
      scale_ = 1.0;
    }
    void add(double normalized) {
      ring_[count_ % ring_.size()] = normalized;
      ++count_;
      const std::size_t kept = std::min(ring_.size(), count_);
      if (kept < ring_.size() / 2 + 1) return;
      std::copy_n(ring_.begin(), kept, sorted_.begin());
      const auto middle = sorted_.begin() + static_cast<std::ptrdiff_t>(kept / 2);
      std::nth_element(sorted_.begin(), middle,
                       sorted_.begin() + static_cast<std::ptrdiff_t>(kept));
      scale_ = std::max(1.0, *middle / chi2_median);
    }
    [[nodiscard]] double scale() const noexcept { return scale_; }

    // The entries of the ring that are in (the first min(n, count) slots), the count and the
    // scale; the sorted copy is a workspace.
    [[nodiscard]] nlohmann::json save() const {
      const std::size_t kept = std::min(ring_.size(), count_);
      nlohmann::json ring = nlohmann::json::array();
      for (std::size_t i = 0; i < kept; ++i) ring.push_back(json_state::number_to_json(ring_[i]));
      return {{"ring", std::move(ring)},
              {"count", count_},
              {"scale", json_state::number_to_json(scale_)}};
    }
    void restore(const nlohmann::json& saved) {
      const std::uint64_t count = json_state::read_count(saved, "count");
      const std::size_t kept = std::min<std::uint64_t>(ring_.size(), count);
      const nlohmann::json& ring = json_state::require_array(json_state::field(saved, "ring"),
                                                             "ring", static_cast<Index>(kept));
      std::vector<double> values = ring_;
      for (std::size_t i = 0; i < kept; ++i) {
        values[i] = json_state::read_double(ring[i], fmt::format("ring[{}]", i));
      }
      const double scale = json_state::read_double_field(saved, "scale");
      ring_.swap(values);
      count_ = static_cast<std::size_t>(count);
      scale_ = scale;
    }

   private:
    std::vector<double> ring_;
    std::vector<double> sorted_;
    std::size_t count_ = 0;
    double scale_ = 1.0;
  };
  static constexpr double chi2_median = 0.4549;  // of χ²(1)
  MedianMisfit model_misfit_;                    // entries whose model errs: misfit_scale()
  MedianMisfit prediction_misfit_;               // every entry: prediction_scale()
  // Workspaces, sized once.
  StateMatrix shift_;
  StateVector shifted_mean_;
  StateMatrix shifted_covariance_;
  StateMatrix prior_precision_;
  StateMatrix identity_;
  StateVector trial_;
  StateVector candidate_;
  StateVector best_;
  StateVector start_;
  StateVector step_;
  StateVector gradient_;
  StateVector difference_;
  StateVector weighted_difference_;
  StateMatrix normal_;
  Matrix<Dynamic, state_size> jacobian_;
  VectorX residuals_;
  OffsetVector error_;
  OffsetVector curvature_error_;
  OffsetMatrix hessian_covariance_;
  OffsetVector slope_;
  OffsetVector velocity_;
  Eigen::LDLT<StateMatrix> factor_;
  Eigen::SelfAdjointEigenSolver<OffsetMatrix> hessian_eigen_;
  OffsetMatrix last_hessian_;  // the last H added, as fitted
  StateVector prior_scale_;
  Eigen::SelfAdjointEigenSolver<StateMatrix> state_eigen_;
};

// The members that do the work are defined out of the class, so not inline: for the sizes
// declared `extern template` at the end of this file, the files that include it do not
// instantiate them (with their Gauss–Newton solve, factorizations and eigensolvers), but link
// the instantiations compiled once in controllers' src/constant_velocity_estimator.cpp.

template <int N>
ConstantVelocityEstimator<N>::ConstantVelocityEstimator(const VectorX& box_width,
                                                        double measurement_variance,
                                                        const ConstantVelocityOptions& options)
    : options_((require_valid("ConstantVelocityOptions", options), options)),
      measurement_variance_(measurement_variance),
      width_(box_width),
      factor_(2 * box_width.size()),
      hessian_eigen_(box_width.size()),
      state_eigen_(2 * box_width.size()) {
  require_finite("box_width", width_);
  if (!(width_.size() > 0) || !(width_.minCoeff() > 0.0)) {
    throw InvalidArgumentError("box_width",
                               "box_width: rule: must have entries, all > 0 (the control box)");
  }
  require_finite("measurement_variance", measurement_variance_);
  require_positive("measurement_variance", measurement_variance_);
  const Index d = width_.size();
  if constexpr (N != Dynamic) require_dimension("box_width", d, N);
  const Index s = 2 * d;
  const Index capacity = options_.max_history;
  times_.assign(static_cast<std::size_t>(capacity), 0);
  controls_.resize(d, capacity);
  applied_.resize(d, capacity);
  values_.resize(capacity);
  half_gradients_.resize(d, capacity);
  hessians_.resize(d, d * capacity);
  qualities_.resize(capacity);
  weights_.resize(capacity);
  model_variances_.resize(capacity);
  const Index lags = options_.change_lag + 1;
  snapshot_times_.assign(static_cast<std::size_t>(lags), 0);
  snapshot_states_.resize(s, lags);
  snapshot_covariances_.resize(d, d * lags);
  prior_mean_.resize(s);
  prior_covariance_.resize(s, s);
  state_.setZero(s);
  covariance_.setIdentity(s, s);
  shift_.setIdentity(s, s);
  shifted_mean_.resize(s);
  shifted_covariance_.resize(s, s);
  prior_precision_.resize(s, s);
  identity_ = StateMatrix::Identity(s, s);
  trial_.resize(s);
  candidate_.resize(s);
  best_.resize(s);
  start_.resize(s);
  step_.resize(s);
  gradient_.resize(s);
  difference_.resize(s);
  weighted_difference_.resize(s);
  normal_.resize(s, s);
  jacobian_.resize(capacity, s);
  residuals_.resize(capacity);
  error_.resize(d);
  curvature_error_.resize(d);
  hessian_covariance_.resize(d, d);
  slope_.resize(d);
  velocity_.resize(d);
  position_.resize(d);
  position_covariance_.resize(d, d);
  prior_scale_.resize(s);
  last_hessian_.resize(d, d);
  model_misfit_.resize(options_.misfit_window);
  prediction_misfit_.resize(options_.misfit_window);
}

template <int N>
void ConstantVelocityEstimator<N>::reset(Index time, const OffsetVector& position,
                                         const OffsetMatrix& position_covariance) {
  const Index d = dimension();
  require_dimension("position", position.size(), d);
  require_finite("position", position);
  require_shape("position_covariance", position_covariance, d, d);
  require_positive_definite("position_covariance", position_covariance);
  prior_mean_.head(d) = position;
  prior_mean_.tail(d).setZero();
  prior_covariance_.setZero();
  prior_covariance_.topLeftCorner(d, d) = position_covariance;
  prior_covariance_.diagonal().tail(d) =
      (options_.velocity_fraction * width_).array().square().matrix();
  prior_time_ = time;
  size_ = 0;
  head_ = 0;
  snapshots_ = 0;
  model_misfit_.clear();
  prediction_misfit_.clear();
  changes_ = 0;
  changed_ = false;
  fitted_ = false;
  fit(time);
}

template <int N>
double ConstantVelocityEstimator<N>::add(Index time, const QuadraticModel<N>& model,
                                         const OffsetVector& control, double z,
                                         double model_variance) {
  const Index d = dimension();
  require_dimension("control", control.size(), d);
  require_dimension("model", model.dimension(), d);
  require_finite("control", control);
  require_finite("z", z);
  require_finite("model_variance", model_variance);
  require_non_negative("model_variance", model_variance);
  if (size_ > 0 && time < time_of(size_ - 1)) {
    throw InvalidArgumentError(
        "time", fmt::format("time: value is {}; rule: must be >= the last time in the history, "
                            "{}",
                            time, time_of(size_ - 1)));
  }
  if (!fitted_ || fit_time_ != time) fit(time);

  if (size_ == options_.max_history) {  // the oldest assembly leaves the ring
    head_ = (head_ + 1) % options_.max_history;
    --size_;
  }
  const Index i = slot(size_);
  times_[static_cast<std::size_t>(i)] = time;
  controls_.col(i) = control - model.center;
  applied_.col(i) = control;
  values_(i) = model.value;
  half_gradients_.col(i) = model.half_gradient;
  // H as fitted may have tiny negative eigenvalues (finite differences along directions the
  // quality ignores); along them the fit would run away, so they are clipped at 0. The
  // surrogate keeps H for many assemblies: an unchanged H reuses the previous entry's.
  if (size_ > 0 && model.hessian == last_hessian_) {
    hessians_.middleCols(i * d, d) = hessians_.middleCols(slot(size_ - 1) * d, d);
  } else {
    last_hessian_ = model.hessian;
    clip_hessian(last_hessian_, i);
  }
  qualities_(i) = z;
  weights_(i) = 1.0 / (measurement_variance_ + model_variance);
  model_variances_(i) = model_variance;
  ++size_;

  // The innovation of z against the prediction at `time` (a = position_, τ = 0).
  const double residual = residual_at(size_ - 1, state_, time);
  curvature_error_.noalias() = position_covariance_ * slope_;
  const double variance = 1.0 / weights_(slot(size_ - 1)) + slope_.dot(curvature_error_);
  const double normalized = residual * residual / variance;
  // The gate's scale counts only entries whose model errs (τ² > 0): an exact model's misfit is
  // the estimate's own error or a change of velocity, which is what the gate is there to see
  // (measured: with every entry, a quadratic twin at d = 32 ran a residual of 0.18 instead of
  // 0.14).
  if (options_.misfit_window > 0 && model_variance > 0.0) model_misfit_.add(normalized);
  if (options_.misfit_window > 0) {
    // prediction_scale() takes the innovation's variance to second order: near the optimum the
    // slope vanishes, and Q² still varies with the estimate's error e ~ N(0, P) through eᵀHe,
    // which adds 2 tr((HP)²) to the variance of Q² and tr((HP)²) / (2 m²) to that of z = m.
    // Without it a plant that is the twin passes audit_misfit at d ≥ 12 (its estimate errs
    // along directions the first-order slope does not see).
    const double predicted = std::max(z - residual, std::numeric_limits<double>::min());
    hessian_covariance_.noalias() =
        hessians_.middleCols(slot(size_ - 1) * d, d) * position_covariance_;
    const double second_order =
        hessian_covariance_.cwiseProduct(hessian_covariance_.transpose()).sum() /
        (2.0 * predicted * predicted);
    prediction_misfit_.add(residual * residual / (variance + second_order));
  }
  return normalized;
}

template <int N>
void ConstantVelocityEstimator<N>::fit(Index time) {
  const Index d = dimension();
  changed_ = false;
  shift_prior(time);
  // Warm start: the last estimate moved to `time` with its velocity.
  if (fitted_) {
    start_ = state_;
    start_.head(d) += static_cast<double>(time - fit_time_) * state_.tail(d);
  } else {
    start_ = shifted_mean_;
  }
  double cost = solve(start_, time, best_);
  if (data_cost_ > static_cast<double>(size_) * options_.change_gate * options_.change_gate) {
    // The warm start explains the data badly: also try its mirror image and the prior mean.
    for (int candidate = 0; candidate < 2; ++candidate) {
      if (candidate == 0) {
        start_ = -start_;
      } else {
        start_ = shifted_mean_;
      }
      // Not into trial_: solve() uses it for its trial steps.
      const double candidate_cost = solve(start_, time, candidate_);
      if (candidate_cost < cost) {
        cost = candidate_cost;
        best_ = candidate_;
      }
    }
  }
  if (size_ > options_.change_window + 2 && recent_misfit(best_, time)) {
    restart_at_change(time);
    start_ = best_;
    solve(start_, time, best_);
    changed_ = true;
    ++changes_;
  }
  state_ = best_;
  finish(time);
}

template <int N>
void ConstantVelocityEstimator<N>::relinearize(Index i, const QuadraticModel<N>& model,
                                               double model_variance) {
  const Index d = dimension();
  if (i < 0 || i >= size_) {
    throw InvalidArgumentError(
        "i", fmt::format("i: value is {}; rule: must lie in [0, {}) (the history)", i, size_));
  }
  require_dimension("model", model.dimension(), d);
  require_finite("model.center", model.center);
  require_finite("model.value", model.value);
  require_finite("model.half_gradient", model.half_gradient);
  require_finite("model.hessian", model.hessian);
  require_finite("model_variance", model_variance);
  require_non_negative("model_variance", model_variance);
  const Index s = slot(i);
  controls_.col(s) = applied_.col(s) - model.center;
  values_(s) = model.value;
  half_gradients_.col(s) = model.half_gradient;
  clip_hessian(model.hessian, s);
  weights_(s) = 1.0 / (measurement_variance_ + model_variance);
  model_variances_(s) = model_variance;
}

template <int N>
nlohmann::json ConstantVelocityEstimator<N>::save() const {
  using json_state::doubles_to_json;
  using json_state::matrix_to_json;
  using json_state::number_to_json;
  const Index d = dimension();
  nlohmann::json history = nlohmann::json::array();
  nlohmann::json hessians = nlohmann::json::array();
  for (Index i = 0; i < size_; ++i) {
    const Index s = slot(i);
    if (i == 0 || hessians_.middleCols(s * d, d) != hessians_.middleCols(slot(i - 1) * d, d)) {
      hessians.push_back(matrix_to_json(hessians_.middleCols(s * d, d)));
    }
    history.push_back({{"time", times_[static_cast<std::size_t>(s)]},
                       {"applied", doubles_to_json(applied_.col(s))},
                       {"control", doubles_to_json(controls_.col(s))},
                       {"value", number_to_json(values_(s))},
                       {"half_gradient", doubles_to_json(half_gradients_.col(s))},
                       {"hessian", hessians.size() - 1},
                       {"quality", number_to_json(qualities_(s))},
                       {"model_variance", number_to_json(model_variances_(s))}});
  }
  nlohmann::json snapshots = nlohmann::json::array();
  const Index kept_snapshots = std::min<Index>(snapshots_, options_.change_lag + 1);
  for (Index i = 0; i < kept_snapshots; ++i) {
    snapshots.push_back(
        {{"time", snapshot_times_[static_cast<std::size_t>(i)]},
         {"state", doubles_to_json(snapshot_states_.col(i))},
         {"covariance", matrix_to_json(snapshot_covariances_.middleCols(i * d, d))}});
  }
  return {{"format", json_format},
          {"dimension", d},
          {"max_history", options_.max_history},
          {"head", head_},
          {"history", std::move(history)},
          {"hessians", std::move(hessians)},
          {"last_hessian", size_ > 0 ? matrix_to_json(last_hessian_) : nlohmann::json(nullptr)},
          {"snapshot_count", snapshots_},
          {"snapshots", std::move(snapshots)},
          {"prior_mean", doubles_to_json(prior_mean_)},
          {"prior_covariance", matrix_to_json(prior_covariance_)},
          {"prior_time", prior_time_},
          {"state", doubles_to_json(state_)},
          {"covariance", matrix_to_json(covariance_)},
          {"fit_time", fit_time_},
          {"fitted", fitted_},
          {"changes", changes_},
          {"changed", changed_},
          {"significant", significant_},
          {"misfit", model_misfit_.save()},
          {"prediction_misfit", prediction_misfit_.save()}};
}

template <int N>
void ConstantVelocityEstimator<N>::restore(const nlohmann::json& saved) {
  using json_state::field;
  using json_state::read_bool;
  using json_state::read_double_field;
  using json_state::read_integer_field;
  const Index d = dimension();
  const Index s = 2 * d;
  const Index capacity = options_.max_history;
  const Index lags = options_.change_lag + 1;
  json_state::require_header(saved, json_format, d);
  require_dimension("max_history", read_integer_field(saved, "max_history"), capacity);
  const Index head = read_integer_field(saved, "head", 0, capacity - 1);

  // The history into copies of the ring buffers, each entry at its slot.
  const nlohmann::json& hessians = json_state::require_array(field(saved, "hessians"), "hessians");
  const nlohmann::json& history = json_state::require_array(field(saved, "history"), "history");
  const auto size = static_cast<Index>(history.size());
  if (size > capacity) {
    throw InvalidArgumentError(
        "history",
        fmt::format("history: has {} entries; rule: at most max_history, {}", size, capacity));
  }
  std::vector<Index> times = times_;
  Matrix<N, Dynamic> controls = controls_;
  Matrix<N, Dynamic> applied = applied_;
  VectorX values = values_;
  Matrix<N, Dynamic> half_gradients = half_gradients_;
  Matrix<N, Dynamic> ring_hessians = hessians_;
  VectorX qualities = qualities_;
  VectorX weights = weights_;
  VectorX model_variances = model_variances_;
  OffsetVector column(d);
  OffsetMatrix hessian(d, d);
  for (Index i = 0; i < size; ++i) {
    json_state::within(fmt::format("history[{}]", i), [&] {
      const nlohmann::json& entry = history[static_cast<std::size_t>(i)];
      const Index at = (head + i) % capacity;
      const Index time = read_integer_field(entry, "time");
      if (i > 0 && time < times[static_cast<std::size_t>((head + i - 1) % capacity)]) {
        throw InvalidArgumentError(
            "time", fmt::format("time: is {}; rule: must be >= the previous entry's", time));
      }
      times[static_cast<std::size_t>(at)] = time;
      json_state::read_doubles(field(entry, "applied"), "applied", column);
      applied.col(at) = column;
      json_state::read_doubles(field(entry, "control"), "control", column);
      controls.col(at) = column;
      values(at) = read_double_field(entry, "value");
      json_state::read_doubles(field(entry, "half_gradient"), "half_gradient", column);
      half_gradients.col(at) = column;
      const Index which =
          read_integer_field(entry, "hessian", 0, static_cast<Index>(hessians.size()) - 1);
      json_state::read_matrix(hessians[static_cast<std::size_t>(which)],
                              fmt::format("hessians[{}]", which), hessian);
      ring_hessians.middleCols(at * d, d) = hessian;
      qualities(at) = read_double_field(entry, "quality");
      const double model_variance = read_double_field(entry, "model_variance");
      require_non_negative("model_variance", model_variance);
      model_variances(at) = model_variance;
      weights(at) = 1.0 / (measurement_variance_ + model_variance);  // as add() forms it
    });
  }
  OffsetMatrix last_hessian = last_hessian_;
  if (size > 0) json_state::read_matrix(field(saved, "last_hessian"), "last_hessian", last_hessian);

  // The snapshots of the last change_lag + 1 fits, at their slots.
  const Index snapshot_count = read_integer_field(saved, "snapshot_count", 0);
  const nlohmann::json& snapshots = json_state::require_array(
      field(saved, "snapshots"), "snapshots", std::min(snapshot_count, lags));
  std::vector<Index> snapshot_times = snapshot_times_;
  Matrix<state_size, Dynamic> snapshot_states = snapshot_states_;
  Matrix<N, Dynamic> snapshot_covariances = snapshot_covariances_;
  StateVector state_column(s);
  for (std::size_t i = 0; i < snapshots.size(); ++i) {
    json_state::within(fmt::format("snapshots[{}]", i), [&] {
      const auto at = static_cast<Index>(i);
      snapshot_times[i] = read_integer_field(snapshots[i], "time");
      json_state::read_doubles(field(snapshots[i], "state"), "state", state_column);
      snapshot_states.col(at) = state_column;
      json_state::read_matrix(field(snapshots[i], "covariance"), "covariance", hessian);
      snapshot_covariances.middleCols(at * d, d) = hessian;
    });
  }

  // The prior and the estimate.
  StateVector prior_mean(s);
  json_state::read_doubles(field(saved, "prior_mean"), "prior_mean", prior_mean);
  StateMatrix prior_covariance(s, s);
  json_state::read_matrix(field(saved, "prior_covariance"), "prior_covariance", prior_covariance);
  const Index prior_time = read_integer_field(saved, "prior_time");
  StateVector state(s);
  json_state::read_doubles(field(saved, "state"), "state", state);
  StateMatrix covariance(s, s);
  json_state::read_matrix(field(saved, "covariance"), "covariance", covariance);
  const Index fit_time = read_integer_field(saved, "fit_time");
  const bool fitted = read_bool(saved, "fitted");
  const Index changes = read_integer_field(saved, "changes", 0);
  const bool changed = read_bool(saved, "changed");
  const bool significant = read_bool(saved, "significant");
  MedianMisfit misfit = model_misfit_;
  const nlohmann::json& saved_misfit = field(saved, "misfit");
  json_state::within("misfit", [&] { misfit.restore(saved_misfit); });
  MedianMisfit prediction_misfit = prediction_misfit_;
  const nlohmann::json& saved_prediction = field(saved, "prediction_misfit");
  json_state::within("prediction_misfit", [&] { prediction_misfit.restore(saved_prediction); });

  // Nothing throws from here on.
  times_.swap(times);
  controls_.swap(controls);
  applied_.swap(applied);
  values_.swap(values);
  half_gradients_.swap(half_gradients);
  hessians_.swap(ring_hessians);
  qualities_.swap(qualities);
  weights_.swap(weights);
  model_variances_.swap(model_variances);
  head_ = head;
  size_ = size;
  last_hessian_ = last_hessian;
  snapshot_times_.swap(snapshot_times);
  snapshot_states_.swap(snapshot_states);
  snapshot_covariances_.swap(snapshot_covariances);
  snapshots_ = snapshot_count;
  prior_mean_ = prior_mean;
  prior_covariance_ = prior_covariance;
  prior_time_ = prior_time;
  state_ = state;
  covariance_ = covariance;
  position_ = state_.head(d);  // as finish() forms them
  position_covariance_ = covariance_.topLeftCorner(d, d);
  fit_time_ = fit_time;
  fitted_ = fitted;
  changes_ = changes;
  changed_ = changed;
  significant_ = significant;
  model_misfit_ = std::move(misfit);
  prediction_misfit_ = std::move(prediction_misfit);
}

// The run-time size: the ActiveController of the experiments, the CLI, the Python module, the
// tests, the benchmarks and the examples.
extern template class ConstantVelocityEstimator<Dynamic>;

}  // namespace twincal
