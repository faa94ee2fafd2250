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
/// and keeps only the assemblies measured since. The gate judges the residuals of the fit as it
/// is made (ChangeTest::now), or, where the owner refits the models that the fit uses beyond
/// their checks' reach, of the fit after that refit (ChangeTest::after_refit, test_change()):
/// a stale model can err there by many σz, which is not a change of the plant. That test also
/// reads the innovations (ConstantVelocityOptions::innovation_window): each z against the
/// prediction made before it joined the fit, which the fit's 2d unknowns cannot bend to.
///
/// Misfit. Residuals larger than σz² + τ_k² explains (a twin whose models err more than their
/// checks say) are measured by the median normalized innovation of the last assemblies, and the
/// change gate and the significance test are taken in those units (ConstantVelocityOptions::
/// misfit_window); for the gate, at most max_misfit_scale of them, since the unit is measured on
/// the residuals the gate judges. With min_gate_unit < 1 (off by default), where no recent
/// model errs, the gate's unit is the plant's own, down to min_gate_unit: a plant measured more
/// precisely than σz² (the paper's is noise-free) shows a turn of its drift far below σz
/// (gate_unit()). After a refit (test_change()), where models err, min_erring_gate_unit (0.01 by
/// default) does the same (refitted_gate_unit()), and the fit itself weighs the assemblies in
/// the plant's unit, down to min_erring_fit_unit (0.01 by default; fit_unit()).
///
/// Relinearization. A model fitted where the estimate put an assembly is used, after later
/// fits, where they put it; the owner can refit it there (entry_point(), relinearize()), which
/// makes the fit Gauss–Newton on the twin itself rather than on the first models.
///
/// Wall (optional). The offset the fit may take can be bounded, per locator, by
/// max_position_fraction of the box width (a stiff penalty beyond it, left out of the
/// covariance): where the twin cannot explain the plant, an offset the quality hardly sees would
/// otherwise explain it, and the estimate can run off without bound
/// (ConstantVelocityOptions::max_position_fraction; none by default).
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

#include "twincal/controllers/active/constant_velocity_options.hpp"
#include "twincal/controllers/active/quadratic_model.hpp"
#include "twincal/controllers/controller_state_json.hpp"
#include "twincal/core/eigen.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/median.hpp"
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

  /// How a fit's Gauss–Newton solve ended.
  enum class SolveStatus {
    none,            ///< no fit in this process yet (a restored estimator until it fits)
    converged,       ///< the step fell below ConstantVelocityOptions::step_tolerance
    no_descent,      ///< ten halvings of the step found no lower cost: a minimum to precision
    max_iterations,  ///< ConstantVelocityOptions::max_iterations steps, each descending
  };
  /// The last solve of a fit (Ceres' TinySolver::Summary): how it ended, its accepted steps,
  /// and its cost (data + prior + the wall, if any) and data cost Σ e_k²/σ_k² at the estimate.
  struct SolveSummary {
    SolveStatus status = SolveStatus::none;
    int iterations = 0;
    double cost = 0.0;
    double data_cost = 0.0;
  };

  [[nodiscard]] Index dimension() const noexcept { return width_.size(); }
  [[nodiscard]] const ConstantVelocityOptions& options() const noexcept { return options_; }
  /// Assemblies in the history.
  [[nodiscard]] Index history_size() const noexcept { return history_.size; }
  /// Changes of velocity declared so far, and whether the last fit declared one.
  [[nodiscard]] Index changes() const noexcept { return estimate_.changes; }
  [[nodiscard]] bool changed() const noexcept { return estimate_.changed; }
  /// The change gate's reading at the last fit: the last change_window entries' mean squared
  /// normalized residual over change_gate² · gate_unit(); changed() holds where it exceeds 1. NaN
  /// where the history was too short to consult the gate.
  [[nodiscard]] double change_ratio() const noexcept { return estimate_.change_ratio; }
  /// Whether the history shows an offset: the fit explains it better than δu = 0 by more than
  /// chance would (see ConstantVelocityOptions::significance).
  [[nodiscard]] bool significant() const noexcept { return estimate_.significant; }
  /// The assembly the last fit estimated, and its (a, b) and covariance.
  [[nodiscard]] Index fit_time() const noexcept { return estimate_.time; }
  [[nodiscard]] const StateVector& state() const noexcept { return estimate_.state; }
  [[nodiscard]] const StateMatrix& covariance() const noexcept { return estimate_.covariance; }
  /// The solve that gave the last fit's estimate (of its starts, the best; after a change of
  /// velocity, the restarted one). Diagnostic: not saved, so none after restore().
  [[nodiscard]] const SolveSummary& last_solve() const noexcept { return last_solve_; }
  /// a, the offset at fit_time(), and its covariance.
  [[nodiscard]] const OffsetVector& position() const noexcept { return estimate_.position; }
  [[nodiscard]] const OffsetMatrix& position_covariance() const noexcept {
    return estimate_.position_covariance;
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

  /// When a fit consults the change gate.
  enum class ChangeTest {
    now,          ///< fit() consults it on its estimate, with the history's models as they are
    after_refit,  ///< fit() does not: its owner refits the models the fit uses beyond their
                  ///< checks' reach (relinearize()), fits again, and calls test_change()
  };

  /// The estimate at assembly `time` from the prior and the history (see the file comment).
  void fit(Index time, ChangeTest test = ChangeTest::now);

  /// Consults the change gate on the last fit, whose models the owner has refitted where it
  /// uses them (ChangeTest::after_refit), in units of refitted_gate_unit(), and the innovations
  /// since the fit last restarted (innovations_beyond_gate()); where either declares a change,
  /// restarts and fits again as fit() does. Nothing before the first fit.
  void test_change();

  /// s², the misfit of the history's entries whose model errs, in units of their residuals'
  /// variance σz² + τ² (>= 1; ConstantVelocityOptions::misfit_window): the unit of the
  /// significance test, and of the change gate up to ConstantVelocityOptions::max_misfit_scale.
  [[nodiscard]] double misfit_scale() const noexcept { return model_misfit_.scale(); }
  /// How badly the estimator predicts the plant: the median normalized innovation ν²/S of the
  /// last misfit_window assemblies, every entry (S = σz² + τ² + the estimate's variance along
  /// the model's slope), over χ²(1)'s median, at least 1; 1 until half the window is in. Unlike
  /// misfit_scale() it counts exact models too, so a plant that is not the twin shows here.
  /// Each innovation is predicted before its entry joins the fit, so, unlike the fit's own
  /// residuals (which 2d unknowns absorb until the history holds well over 2d entries), it
  /// speaks at any d.
  [[nodiscard]] double prediction_scale() const noexcept { return prediction_misfit_.scale(); }
  /// The change gate's unit, in units of σz²: min(misfit_scale(), max_misfit_scale). With
  /// ConstantVelocityOptions::min_gate_unit < 1 (off by default), where none of the last
  /// misfit_window entries' models erred, the plant's own instead: the median innovation
  /// ν²/(σz² + τ²) of the last misfit_window entries over χ²(1)'s median, within
  /// [min_gate_unit, 1] (1 until half the window is in).
  [[nodiscard]] double gate_unit() const noexcept {
    return recent_models_err() ? misfit_unit() : plant_unit(options_.min_gate_unit);
  }
  /// The change gate's unit in test_change(): gate_unit(), except where one of the last
  /// misfit_window entries' models erred and ConstantVelocityOptions::min_erring_gate_unit < 1:
  /// the plant's own there, the median innovation ν²/(σz² + τ²) over χ²(1)'s median, within
  /// [min_erring_gate_unit, 1].
  [[nodiscard]] double refitted_gate_unit() const noexcept {
    return plant_unit(recent_models_err() ? options_.min_erring_gate_unit : options_.min_gate_unit);
  }
  /// The unit s of σz² in the fit's weights 1/(s·σz² + τ²), as of the last fit: where one of the
  /// last misfit_window entries' models erred and ConstantVelocityOptions::min_erring_fit_unit
  /// < 1, the plant's own, the median innovation ν²/(σz² + τ²) over χ²(1)'s median within
  /// [min_erring_fit_unit, 1] (1 until half the window is in); 1 elsewhere, and for the
  /// change_lag assemblies from one whose innovation ν²/(σz² + τ²) exceeded change_gate² ·
  /// max_misfit_scale.
  [[nodiscard]] double fit_unit() const noexcept { return fit_unit_; }

  /// The time of history entry i (0 the oldest).
  [[nodiscard]] Index entry_time(Index i) const noexcept { return time_of(i); }

  /// Where entry i was measured in the twin's frame under the last fit, u_i − δu_i (δu_i = a +
  /// (t_i − t) b), and how far that lies from its model's centre, in `offset`.
  void entry_point(Index i, OffsetVector& point, OffsetVector& offset) const {
    const Index d = dimension();
    const Index s = slot(i);
    const double tau =
        static_cast<double>(history_.times[static_cast<std::size_t>(s)] - estimate_.time);
    point = history_.applied.col(s) - estimate_.state.head(d) - tau * estimate_.state.tail(d);
    offset = history_.controls.col(s) - estimate_.state.head(d) - tau * estimate_.state.tail(d);
  }

  /// τ² of entry i: its residual's variance beyond σz².
  [[nodiscard]] double entry_model_variance(Index i) const noexcept {
    return history_.model_variances(slot(i));
  }

  /// The Hessian entry i's model uses (as fitted, negative eigenvalues clipped at 0).
  [[nodiscard]] auto entry_hessian(Index i) const {
    const Index d = dimension();
    return history_.hessians.middleCols(slot(i) * d, d);
  }

  /// Entry i's squared residual under the last fit over its variance, (z_i − m_i)² / (σz² + τ_i²),
  /// m_i its model at the offset the fit gives its time, as the fit weighs it. (Not const: it
  /// is the fit's own residual, computed in the fit's workspaces.)
  [[nodiscard]] double normalized_residual(Index i);

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
  /// last change_lag + 2 assemblies fitted, the prior, the estimate with its flags and counters,
  /// and the misfit scales with their ring. Not last_solve(), nor the workspaces of a fit
  /// (Gauss–Newton buffers, shifted prior, factorizations), which every fit rewrites before reading
  /// them, nor the weights 1/(σz² + τ²), recomputed from τ².
  [[nodiscard]] nlohmann::json save() const;

  /// Restores a snapshot of save() into an estimator of the same box, σz² and options.
  /// @throws InvalidArgumentError, DimensionMismatchError, NonFiniteError naming the field
  ///         ("history[3].quality"); the estimator unchanged.
  void restore(const nlohmann::json& saved);

 private:
  // Stores `hessian`, its negative eigenvalues clipped at 0, in ring slot i.
  void clip_hessian(const OffsetMatrix& hessian, Index i) {
    const Index d = dimension();
    work_.hessian_eigen.compute(hessian);
    if (work_.hessian_eigen.eigenvalues().minCoeff() < 0.0) {
      history_.hessians.middleCols(i * d, d).noalias() =
          work_.hessian_eigen.eigenvectors() *
          work_.hessian_eigen.eigenvalues().cwiseMax(0.0).asDiagonal() *
          work_.hessian_eigen.eigenvectors().transpose();
    } else {
      history_.hessians.middleCols(i * d, d) = hessian;
    }
  }

  [[nodiscard]] Index slot(Index i) const noexcept {
    return (history_.head + i) % options_.max_history;
  }
  [[nodiscard]] Index time_of(Index i) const noexcept {
    return history_.times[static_cast<std::size_t>(slot(i))];
  }

  // The prior moved from prior_.time to `time` along the constant velocity: θ_t = M θ_p with
  // M = [I, Δ I; 0, I], Σ_t = M Σ_p Mᵀ, and its precision.
  void shift_prior(Index time) {
    const Index d = dimension();
    const double delta = static_cast<double>(time - prior_.time);
    work_.shift.topRightCorner(d, d).diagonal().setConstant(delta);
    work_.shifted_mean.noalias() = work_.shift * prior_.mean;
    work_.normal.noalias() = work_.shift * prior_.covariance;
    work_.shifted_covariance.noalias() = work_.normal * work_.shift.transpose();
    symmetrize(work_.shifted_covariance);
    cap_prior();
    work_.factor.compute(work_.shifted_covariance);
    work_.prior_precision = work_.factor.solve(work_.identity);
    symmetrize(work_.prior_precision);
  }

  // The prior never claims more uncertainty than the start's: in units of the start's standard
  // deviations (position_fraction · width, velocity_fraction · width) its eigenvalues are capped
  // at 1. Without the cap, directions the quality barely sees (a door's H has rank ≈ 3) would
  // let the velocity's uncertainty grow the offset's without bound, and the probes with it.
  void cap_prior() {
    const Index d = dimension();
    work_.prior_scale.head(d) = options_.position_fraction * width_;
    work_.prior_scale.tail(d) = options_.velocity_fraction * width_;
    const bool beyond =
        (work_.shifted_covariance.diagonal().array() > work_.prior_scale.array().square()).any();
    if (!beyond) return;
    work_.normal = work_.prior_scale.cwiseInverse().asDiagonal() * work_.shifted_covariance *
                   work_.prior_scale.cwiseInverse().asDiagonal();
    work_.state_eigen.compute(work_.normal);
    work_.normal.noalias() = work_.state_eigen.eigenvectors() *
                             work_.state_eigen.eigenvalues().cwiseMin(1.0).asDiagonal() *
                             work_.state_eigen.eigenvectors().transpose();
    work_.shifted_covariance =
        work_.prior_scale.asDiagonal() * work_.normal * work_.prior_scale.asDiagonal();
  }

  // z − m for history entry i (r = v − a − τ b); writes work_.slope = ∂m/∂a. A non-positive model
  // value (a fitted H may be indefinite) is clamped, with a zero slope.
  double residual_at(Index i, const StateVector& state, Index time) {
    const Index d = dimension();
    const Index s = slot(i);
    const double tau = static_cast<double>(history_.times[static_cast<std::size_t>(s)] - time);
    work_.error = history_.controls.col(s) - state.head(d) - tau * state.tail(d);
    work_.curvature_error.noalias() = history_.hessians.middleCols(s * d, d) * work_.error;
    const double squared = history_.values(s) +
                           2.0 * history_.half_gradients.col(s).dot(work_.error) +
                           work_.error.dot(work_.curvature_error);
    const double floor = 1e-12 * (1.0 + std::abs(history_.values(s)));
    if (squared > floor) {
      const double model = std::sqrt(squared);
      work_.slope = -(history_.half_gradients.col(s) + work_.curvature_error) / model;
      return history_.qualities(s) - model;
    }
    work_.slope.setZero();
    return history_.qualities(s) - std::sqrt(floor);
  }

  // Normalized residuals e_k/σ_k and their Jacobian of the history at `state`; returns the data
  // cost Σ e_k²/σ_k², σ_k² = s·σz² + τ_k², s = fit_unit().
  double evaluate(const StateVector& state, Index time, bool jacobian) {
    const Index d = dimension();
    double cost = 0.0;
    for (Index i = 0; i < history_.size; ++i) {
      const Index k = slot(i);
      // The fit's weight, 1/(s·σz² + τ²) (fit_unit()); history_.weights keeps 1/(σz² + τ²),
      // in which the gate and the innovations are read.
      const double scale =
          std::sqrt(1.0 / (fit_unit_ * measurement_variance_ + history_.model_variances(k)));
      const double e = scale * residual_at(i, state, time);
      work_.residuals(i) = e;
      cost += e * e;
      if (jacobian) {
        const double tau = static_cast<double>(time_of(i) - time);
        work_.jacobian.row(i).head(d) = scale * work_.slope.transpose();
        work_.jacobian.row(i).tail(d) = (scale * tau) * work_.slope.transpose();
      }
    }
    return cost;
  }

  // Gauss–Newton with step halving from `start`; writes the minimizer to `out`. The
  // Gauss–Newton matrix at the estimate is formed once, by finish().
  SolveSummary solve(const StateVector& start, Index time, StateVector& out) {
    SolveSummary summary{.status = SolveStatus::max_iterations};
    out = start;
    summary.data_cost = evaluate(out, time, true);
    summary.cost = summary.data_cost + penalty_cost(out);
    for (int iteration = 0; iteration < options_.max_iterations; ++iteration) {
      assemble(out);
      work_.step = work_.factor.solve(work_.gradient);
      double scale = 1.0;
      bool improved = false;
      for (int halving = 0; halving < 10 && !improved; ++halving) {
        if (halving > 0) scale *= 0.5;
        work_.trial = out + scale * work_.step;
        const double trial_data = evaluate(work_.trial, time, false);
        const double trial_cost = trial_data + penalty_cost(work_.trial);
        if (trial_cost <= summary.cost) {
          improved = true;
          summary.data_cost = trial_data;
          summary.cost = trial_cost;
        }
      }
      if (!improved) {
        summary.status = SolveStatus::no_descent;
        break;
      }
      out = work_.trial;
      summary.iterations = iteration + 1;
      if (scale * work_.step.norm() <= options_.step_tolerance * (1.0 + out.norm())) {
        summary.status = SolveStatus::converged;
        break;
      }
      if (iteration + 1 < options_.max_iterations) evaluate(out, time, true);  // for assemble()
    }
    return summary;
  }

  // What the fit adds to the data cost: the prior's, and the wall's where there is one.
  double penalty_cost(const StateVector& state) {
    return prior_cost(state) + wall_cost(state, false);
  }

  double prior_cost(const StateVector& state) {
    work_.difference = state - work_.shifted_mean;
    work_.weighted_difference.noalias() = work_.prior_precision * work_.difference;
    return work_.difference.dot(work_.weighted_difference);
  }

  // The wall at max_position_fraction · width: Σ (excess_i / σ_i)² over the locators whose
  // offset a = state.head(d) lies beyond it, σ_i = wall_scale · width_i, so that an excess of
  // wall_scale of the box costs what one σ of a residual does (a wall, not a preference).
  // With `into_normal`, adds its gradient and Gauss–Newton curvature to work_.gradient and
  // work_.normal (after assemble() has formed them).
  double wall_cost(const StateVector& state, bool into_normal) {
    double cost = 0.0;
    if (!std::isfinite(options_.max_position_fraction)) return cost;
    for (Index i = 0; i < dimension(); ++i) {
      const double excess = std::abs(state(i)) - options_.max_position_fraction * width_(i);
      if (excess <= 0.0) continue;
      const double sigma = wall_scale * width_(i);
      const double precision = 1.0 / (sigma * sigma);
      cost += precision * excess * excess;
      if (into_normal) {
        work_.normal(i, i) += precision;
        work_.gradient(i) -= precision * std::copysign(excess, state(i));
      }
    }
    return cost;
  }

  // work_.normal = JᵀJ + Λ, work_.gradient = Jᵀe − Λ(θ − μ) (J and e normalized by σ_k), with
  // the wall's terms where `with_wall`, factored; needs evaluate(·, true).
  void assemble(const StateVector& state, bool with_wall = true) {
    const Index n = history_.size;
    work_.normal = work_.prior_precision;
    work_.normal.noalias() += work_.jacobian.topRows(n).transpose() * work_.jacobian.topRows(n);
    prior_cost(state);
    work_.gradient = -work_.weighted_difference;
    work_.gradient.noalias() += work_.jacobian.topRows(n).transpose() * work_.residuals.head(n);
    if (with_wall) wall_cost(state, true);
    work_.factor.compute(work_.normal);
  }

  // The models' misfit scale as the gate's unit: min(misfit_scale(), max_misfit_scale).
  [[nodiscard]] double misfit_unit() const noexcept {
    return std::min(model_misfit_.scale(), options_.max_misfit_scale);
  }
  // The plant's own unit, the median innovation ν²/(σz² + τ²) over χ²(1)'s median, within
  // [floor, 1]; a floor of 1 (the option off) gives misfit_unit().
  [[nodiscard]] double plant_unit(double floor) const noexcept {
    if (floor >= 1.0) return misfit_unit();
    return std::clamp(innovation_misfit_.unfloored(), floor, 1.0);
  }

  // fit_unit() for the history as it is now: plant_unit() where recent models err (1 until half
  // its window is in) and the fit predicted the plant of the last change_lag assemblies (no
  // innovation ν²/(σz² + τ²) beyond change_gate² · max_misfit_scale, what the gate accepts at
  // its widest); 1 elsewhere or with the option off (where plant_unit() would give the misfit
  // scale).
  void update_fit_unit() noexcept {
    const double unpredicted =
        options_.change_gate * options_.change_gate * options_.max_misfit_scale;
    fit_unit_ = options_.min_erring_fit_unit < 1.0 && recent_models_err() &&
                        !innovation_misfit_.any_recent_beyond(
                            static_cast<std::size_t>(options_.change_lag), unpredicted)
                    ? plant_unit(options_.min_erring_fit_unit)
                    : 1.0;
  }

  // Whether one of the last misfit_window entries' models erred (τ² > 0).
  [[nodiscard]] bool recent_models_err() const noexcept {
    const Index recent = std::min(history_.size, options_.misfit_window);
    for (Index i = history_.size - recent; i < history_.size; ++i) {
      if (history_.model_variances(slot(i)) > 0.0) return true;
    }
    return false;
  }

  // The root-mean-square normalized residual of the last change_window assemblies beyond the
  // gate, in units of `unit` (gate_unit() or refitted_gate_unit()); the reading into
  // estimate_.change_ratio.
  bool recent_misfit(const StateVector& state, Index time, double unit) {
    const Index window = options_.change_window;
    double sum = 0.0;
    for (Index i = history_.size - window; i < history_.size; ++i) {
      const double e = residual_at(i, state, time);
      sum += history_.weights(slot(i)) * e * e;
    }
    const double mean = sum / static_cast<double>(window);
    const double allowed = options_.change_gate * options_.change_gate * unit;
    estimate_.change_ratio = mean / allowed;
    return mean > allowed;
  }

  // The innovations' change test (ConstantVelocityOptions::innovation_window): each of the last
  // innovation_window normalized innovations beyond 1 and their mean beyond change_gate² in
  // their own unit (at least 1), once max(innovation_window, 2d) have joined since the last
  // restart. Where models err that unit is misfit_scale() itself, not the gate's capped one:
  // innovations are judged against what innovations run at (on a noisy plant with erring models
  // ν²/S ran at 20–60 while the gate's unit stopped at max_misfit_scale, and the test restarted
  // fits that were right). Until that scale is known (half its window in) the test waits: the
  // innovations have no unit to be judged in yet.
  [[nodiscard]] bool innovations_beyond_gate() const noexcept {
    if (options_.innovation_window <= 0) return false;
    const bool models_err = recent_models_err();
    if (models_err && !model_misfit_.known()) return false;
    const auto needed =
        static_cast<std::size_t>(std::max(options_.innovation_window, 2 * dimension()));
    const double unit = models_err ? misfit_scale() : gate_unit();
    return recent_innovations_.beyond(
        needed, options_.change_gate * options_.change_gate * std::max(1.0, unit));
  }

  // A change of velocity declared at `time`: restarts (restart_at_change()) and solves from
  // `from` (which may be work_.best) into work_.best.
  SolveSummary restart_from(const StateVector& from, Index time) {
    work_.start = from;
    restart_at_change(time);
    estimate_.changed = true;
    ++estimate_.changes;
    return solve(work_.start, time, work_.best);
  }

  // A change of velocity: the prior becomes the estimate of change_lag assemblies ago, widened
  // along its velocity's line and by the position floor, and the history keeps the assemblies
  // measured since.
  void restart_at_change(Index time) {
    const Index d = dimension();
    const Index slots = snapshot_slots();
    // The snapshots before `time` (a refit's own is not one of them); the oldest of their last
    // change_lag + 1 (or the first, early on).
    Index before = fits_.count;
    if (before > 0 && fits_.times[static_cast<std::size_t>((before - 1) % slots)] == time) {
      --before;
    }
    const Index oldest =
        before <= options_.change_lag + 1 ? 0 : (before - options_.change_lag - 1) % slots;
    const Index restart_time = fits_.times[static_cast<std::size_t>(oldest)];
    work_.velocity = fits_.states.col(oldest).tail(d);
    prior_.mean.head(d) = fits_.states.col(oldest).head(d);
    prior_.mean.tail(d).setZero();
    prior_.covariance.setZero();
    prior_.covariance.topLeftCorner(d, d) =
        fits_.covariances.middleCols(oldest * d, d) +
        options_.change_position_spread * work_.velocity * work_.velocity.transpose();
    prior_.covariance.bottomRightCorner(d, d) =
        options_.change_velocity_spread * work_.velocity * work_.velocity.transpose();
    prior_.covariance.diagonal().tail(d) +=
        (options_.change_velocity_floor_fraction * width_).array().square().matrix();
    prior_.covariance.diagonal().head(d) +=
        (options_.change_position_floor_fraction * width_).array().square().matrix();
    prior_.time = restart_time;
    recent_innovations_.clear();  // they are what the restart answers
    while (history_.size > 0 && time_of(0) < restart_time) {
      history_.head = (history_.head + 1) % options_.max_history;
      --history_.size;
    }
    shift_prior(time);
  }

  // The covariance (the inverse Gauss–Newton matrix at estimate_.state), the position and a
  // snapshot.
  void finish(Index time) {
    const Index d = dimension();
    // Significance: the fit against "no offset", Δ = cost(0) − cost(θ̂) over the history, which
    // is χ² with 2d degrees of freedom when there is none; beyond its mean + k·sd it is real.
    work_.trial.setZero();
    const double no_offset = evaluate(work_.trial, time, false);
    const double fitted =
        evaluate(estimate_.state, time, true);  // and the Gauss–Newton matrix there
    const double dof = static_cast<double>(2 * d);
    estimate_.significant = (no_offset - fitted) / model_misfit_.scale() >
                            dof + options_.significance * std::sqrt(2.0 * dof);
    // The covariance leaves the wall out: it says where the offset cannot be, not how well the
    // data place it, and its curvature would pin a locator at the wall for good.
    assemble(estimate_.state, false);
    estimate_.covariance = work_.factor.solve(work_.identity);
    symmetrize(estimate_.covariance);
    estimate_.position = estimate_.state.head(d);
    estimate_.position_covariance = estimate_.covariance.topLeftCorner(d, d);
    estimate_.time = time;
    estimate_.fitted = true;
    // One snapshot per assembly: a refit of the same time (after relinearization) replaces its
    // fit, so a change restarts from change_lag assemblies ago, not change_lag fits.
    const Index slots = snapshot_slots();
    const bool refit =
        fits_.count > 0 && fits_.times[static_cast<std::size_t>((fits_.count - 1) % slots)] == time;
    if (!refit) ++fits_.count;
    const Index i = (fits_.count - 1) % slots;
    fits_.times[static_cast<std::size_t>(i)] = time;
    fits_.states.col(i) = estimate_.state;
    fits_.covariances.middleCols(i * d, d) = estimate_.position_covariance;
  }

  // The state save() writes, in four parts that restore() reads whole and commits at once.
  // The history: a ring of max_history entries from slot `head`, `size` of them in use.
  struct History {
    std::vector<Index> times;
    Matrix<N, Dynamic> controls;  // u_k − v_k, v_k the centre of entry k's model
    Matrix<N, Dynamic> applied;   // u_k
    VectorX values;
    Matrix<N, Dynamic> half_gradients;
    Matrix<N, Dynamic> hessians;  // d × d blocks side by side
    VectorX qualities;
    VectorX weights;          // 1/(σz² + τ_k²)
    VectorX model_variances;  // τ_k²
    Index head = 0;
    Index size = 0;
  };
  // The estimate of each of the last snapshot_slots() assemblies fitted (`count` so far; the k-th
  // at slot k mod snapshot_slots()): change_lag + 1 before the assembly a refit fits again.
  [[nodiscard]] Index snapshot_slots() const noexcept { return options_.change_lag + 2; }
  struct FitSnapshots {
    std::vector<Index> times;
    Matrix<state_size, Dynamic> states;
    Matrix<N, Dynamic> covariances;
    Index count = 0;
  };
  // The prior at `time`.
  struct Prior {
    StateVector mean;
    StateMatrix covariance;
    Index time = 0;
  };
  // The estimate at `time`, (a, b) and its covariance, with the flags of the fit that gave it.
  struct Estimate {
    StateVector state;
    StateMatrix covariance;
    OffsetVector position;
    OffsetMatrix position_covariance;
    Index time = 0;
    bool fitted = false;
    Index changes = 0;
    bool changed = false;
    bool significant = false;
    double change_ratio = std::numeric_limits<double>::quiet_NaN();
  };

  // The scratch of a fit, sized once by the constructor (no allocation per step): every fit
  // writes each of them before it reads it, so none is state (save() leaves them out).
  struct Workspace {
    void resize(Index d, Index capacity) {
      const Index s = 2 * d;
      shift.setIdentity(s, s);
      shifted_mean.resize(s);
      shifted_covariance.resize(s, s);
      prior_precision.resize(s, s);
      identity = StateMatrix::Identity(s, s);
      prior_scale.resize(s);
      trial.resize(s);
      candidate.resize(s);
      best.resize(s);
      start.resize(s);
      step.resize(s);
      gradient.resize(s);
      difference.resize(s);
      weighted_difference.resize(s);
      normal.resize(s, s);
      jacobian.resize(capacity, s);
      residuals.resize(capacity);
      error.resize(d);
      curvature_error.resize(d);
      hessian_covariance.resize(d, d);
      slope.resize(d);
      velocity.resize(d);
      factor = Eigen::LDLT<StateMatrix>(s);
      hessian_eigen = Eigen::SelfAdjointEigenSolver<OffsetMatrix>(d);
      state_eigen = Eigen::SelfAdjointEigenSolver<StateMatrix>(s);
    }

    // The prior moved to the fit's time (shift_prior) and its precision.
    StateMatrix shift;
    StateVector shifted_mean;
    StateMatrix shifted_covariance;
    StateMatrix prior_precision;
    StateMatrix identity;
    StateVector prior_scale;
    // Gauss–Newton: starts, trial steps, the normal equations and their factorization.
    StateVector trial;
    StateVector candidate;
    StateVector best;
    StateVector start;
    StateVector step;
    StateVector gradient;
    StateVector difference;
    StateVector weighted_difference;
    StateMatrix normal;
    Matrix<Dynamic, state_size> jacobian;
    VectorX residuals;
    Eigen::LDLT<StateMatrix> factor;
    // One entry's residual and slope, and the eigensolvers of H and of the prior's cap.
    OffsetVector error;
    OffsetVector curvature_error;
    OffsetMatrix hessian_covariance;
    OffsetVector slope;
    OffsetVector velocity;
    Eigen::SelfAdjointEigenSolver<OffsetMatrix> hessian_eigen;
    Eigen::SelfAdjointEigenSolver<StateMatrix> state_eigen;
  };

  ConstantVelocityOptions options_;
  double measurement_variance_;
  double fit_unit_ = 1.0;  // fit_unit(), set by update_fit_unit()
  VectorX width_;
  // The history, a ring of max_history assemblies starting at history_.head.
  History history_;
  FitSnapshots fits_;
  Prior prior_;
  Estimate estimate_;
  // A ring of n values, `count` of them added so far, as saved: the slots in use (the first
  // min(n, count)) and the count.
  [[nodiscard]] static nlohmann::json save_ring(const std::vector<double>& ring,
                                                std::size_t count) {
    const std::size_t kept = std::min(ring.size(), count);
    nlohmann::json values = nlohmann::json::array();
    for (std::size_t i = 0; i < kept; ++i) values.push_back(json_state::number_to_json(ring[i]));
    return {{"ring", std::move(values)}, {"count", count}};
  }
  // Reads what save_ring() wrote into `ring` (its size n kept) and returns the count.
  static std::size_t restore_ring(const nlohmann::json& saved, std::vector<double>& ring) {
    const std::uint64_t count = json_state::read_count(saved, "count");
    const std::size_t kept = std::min<std::uint64_t>(ring.size(), count);
    const nlohmann::json& values = json_state::require_array(json_state::field(saved, "ring"),
                                                             "ring", static_cast<Index>(kept));
    for (std::size_t i = 0; i < kept; ++i) {
      ring[i] = json_state::read_double(values[i], fmt::format("ring[{}]", i));
    }
    return static_cast<std::size_t>(count);
  }

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
      unfloored_ = 1.0;
    }
    void add(double normalized) {
      ring_[count_ % ring_.size()] = normalized;
      ++count_;
      unfloored_ = median_scale(std::min(ring_.size(), count_));
      scale_ = std::max(1.0, unfloored_);
    }
    [[nodiscard]] double scale() const noexcept { return scale_; }
    /// The median over χ²(1)'s, not floored at 1 (1 until half of n are in).
    [[nodiscard]] double unfloored() const noexcept { return unfloored_; }
    /// Whether one of the last n entries (at most those in the ring) exceeds `threshold`.
    [[nodiscard]] bool any_recent_beyond(std::size_t n, double threshold) const noexcept {
      const std::size_t recent = std::min({ring_.size(), count_, n});
      for (std::size_t k = 1; k <= recent; ++k) {
        if (ring_[(count_ - k) % ring_.size()] > threshold) return true;
      }
      return false;
    }
    /// Whether half of n are in: the scale is the entries' median, not the 1 it starts at.
    [[nodiscard]] bool known() const noexcept { return is_known(std::min(ring_.size(), count_)); }

    // The entries of the ring that are in (the first min(n, count) slots), the count and the
    // scale; the sorted copy is a workspace.
    [[nodiscard]] nlohmann::json save() const {
      nlohmann::json saved = save_ring(ring_, count_);
      saved["scale"] = json_state::number_to_json(scale_);
      return saved;
    }
    void restore(const nlohmann::json& saved) {
      std::vector<double> values = ring_;
      const std::size_t count = restore_ring(saved, values);
      const double scale = json_state::read_double_field(saved, "scale");
      ring_.swap(values);
      count_ = count;
      scale_ = scale;
      // Not saved: it follows from the ring as add() computed it.
      unfloored_ = median_scale(std::min(ring_.size(), count_));
    }

   private:
    // Whether `kept` entries are half of n: from then on the scale is their median.
    [[nodiscard]] bool is_known(std::size_t kept) const noexcept {
      return kept >= ring_.size() / 2 + 1;
    }
    // The median of the first `kept` entries over χ²(1)'s; 1 until half of n are in.
    [[nodiscard]] double median_scale(std::size_t kept) {
      if (!is_known(kept)) return 1.0;
      return median_of_first(ring_, kept, sorted_) / chi2_median;
    }

    std::vector<double> ring_;
    std::vector<double> sorted_;
    std::size_t count_ = 0;
    double scale_ = 1.0;
    double unfloored_ = 1.0;
  };
  // The normalized innovations ν²/S since the fit last (re)started, the last n of them kept:
  // the innovations' change test (innovations_beyond_gate()).
  class RecentInnovations {
   public:
    void resize(Index n) { ring_.assign(static_cast<std::size_t>(n), 0.0); }
    void clear() noexcept { count_ = 0; }
    void add(double normalized) noexcept {
      if (ring_.empty()) return;
      ring_[count_ % ring_.size()] = normalized;
      ++count_;
    }
    // Whether at least `needed` (>= n > 0) have joined, each of the last n exceeds 1 and their
    // mean exceeds `allowed`.
    [[nodiscard]] bool beyond(std::size_t needed, double allowed) const noexcept {
      if (ring_.empty() || count_ < needed) return false;
      double sum = 0.0;
      for (const double normalized : ring_) {
        if (!(normalized > 1.0)) return false;
        sum += normalized;
      }
      return sum > allowed * static_cast<double>(ring_.size());
    }

    [[nodiscard]] nlohmann::json save() const { return save_ring(ring_, count_); }
    void restore(const nlohmann::json& saved) {
      std::vector<double> values = ring_;
      const std::size_t count = restore_ring(saved, values);
      ring_.swap(values);
      count_ = count;
    }

   private:
    std::vector<double> ring_;
    std::size_t count_ = 0;
  };
  static constexpr double chi2_median = 0.4549;  // of χ²(1)
  static constexpr double wall_scale = 1e-4;     // wall_cost(): the wall's σ / box width
  MedianMisfit model_misfit_;                    // entries whose model errs: misfit_scale()
  MedianMisfit prediction_misfit_;               // every entry: prediction_scale()
  MedianMisfit innovation_misfit_;               // every entry, ν² / (σz² + τ²): gate_unit()
  RecentInnovations recent_innovations_;         // since the last restart: the innovations' test
  OffsetMatrix last_hessian_;                    // the last H added, as fitted
  SolveSummary last_solve_;
  Workspace work_;
};

// The members that do the work are defined out of the class, so not inline: for the sizes
// declared `extern template` at the end of this file, the files that include it do not
// instantiate them (with their Gauss–Newton solve, factorizations and eigensolvers), but link
// the instantiations compiled once in controllers' src/active/constant_velocity_estimator.cpp.

template <int N>
ConstantVelocityEstimator<N>::ConstantVelocityEstimator(const VectorX& box_width,
                                                        double measurement_variance,
                                                        const ConstantVelocityOptions& options)
    : options_((require_valid("ConstantVelocityOptions", options), options)),
      measurement_variance_(measurement_variance),
      width_(box_width) {
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
  history_.times.assign(static_cast<std::size_t>(capacity), 0);
  history_.controls.resize(d, capacity);
  history_.applied.resize(d, capacity);
  history_.values.resize(capacity);
  history_.half_gradients.resize(d, capacity);
  history_.hessians.resize(d, d * capacity);
  history_.qualities.resize(capacity);
  history_.weights.resize(capacity);
  history_.model_variances.resize(capacity);
  const Index slots = snapshot_slots();
  fits_.times.assign(static_cast<std::size_t>(slots), 0);
  fits_.states.resize(s, slots);
  fits_.covariances.resize(d, d * slots);
  prior_.mean.resize(s);
  prior_.covariance.resize(s, s);
  estimate_.state.setZero(s);
  estimate_.covariance.setIdentity(s, s);
  work_.resize(d, capacity);
  estimate_.position.resize(d);
  estimate_.position_covariance.resize(d, d);
  last_hessian_.resize(d, d);
  model_misfit_.resize(options_.misfit_window);
  prediction_misfit_.resize(options_.misfit_window);
  innovation_misfit_.resize(options_.misfit_window);
  recent_innovations_.resize(options_.innovation_window);
}

template <int N>
void ConstantVelocityEstimator<N>::reset(Index time, const OffsetVector& position,
                                         const OffsetMatrix& position_covariance) {
  const Index d = dimension();
  require_dimension("position", position.size(), d);
  require_finite("position", position);
  require_shape("position_covariance", position_covariance, d, d);
  require_positive_definite("position_covariance", position_covariance);
  prior_.mean.head(d) = position;
  prior_.mean.tail(d).setZero();
  prior_.covariance.setZero();
  prior_.covariance.topLeftCorner(d, d) = position_covariance;
  prior_.covariance.diagonal().tail(d) =
      (options_.velocity_fraction * width_).array().square().matrix();
  prior_.time = time;
  history_.size = 0;
  history_.head = 0;
  fits_.count = 0;
  model_misfit_.clear();
  prediction_misfit_.clear();
  innovation_misfit_.clear();
  recent_innovations_.clear();
  fit_unit_ = 1.0;
  estimate_.changes = 0;
  estimate_.changed = false;
  estimate_.fitted = false;
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
  if (history_.size > 0 && time < time_of(history_.size - 1)) {
    throw InvalidArgumentError(
        "time", fmt::format("time: value is {}; rule: must be >= the last time in the history, "
                            "{}",
                            time, time_of(history_.size - 1)));
  }
  if (!estimate_.fitted || estimate_.time != time) fit(time);

  if (history_.size == options_.max_history) {  // the oldest assembly leaves the ring
    history_.head = (history_.head + 1) % options_.max_history;
    --history_.size;
  }
  const Index i = slot(history_.size);
  history_.times[static_cast<std::size_t>(i)] = time;
  history_.controls.col(i) = control - model.center;
  history_.applied.col(i) = control;
  history_.values(i) = model.value;
  history_.half_gradients.col(i) = model.half_gradient;
  // H as fitted may have tiny negative eigenvalues (finite differences along directions the
  // quality ignores); along them the fit would run away, so they are clipped at 0. The
  // surrogate keeps H for many assemblies: an unchanged H reuses the previous entry's.
  if (history_.size > 0 && model.hessian == last_hessian_) {
    history_.hessians.middleCols(i * d, d) =
        history_.hessians.middleCols(slot(history_.size - 1) * d, d);
  } else {
    last_hessian_ = model.hessian;
    clip_hessian(last_hessian_, i);
  }
  history_.qualities(i) = z;
  history_.weights(i) = 1.0 / (measurement_variance_ + model_variance);
  history_.model_variances(i) = model_variance;
  ++history_.size;

  // The innovation of z against the prediction at `time` (a = estimate_.position, τ = 0).
  const double residual = residual_at(history_.size - 1, estimate_.state, time);
  work_.curvature_error.noalias() = estimate_.position_covariance * work_.slope;
  const double variance =
      1.0 / history_.weights(slot(history_.size - 1)) + work_.slope.dot(work_.curvature_error);
  const double normalized = residual * residual / variance;
  // The gate's scale counts only entries whose model errs (τ² > 0): an exact model's misfit is
  // the estimate's own error or a change of velocity, which is what the gate is there to see
  // (measured: with every entry, a quadratic twin at d = 32 ran a residual of 0.18 instead of
  // 0.14).
  if (options_.misfit_window > 0 && model_variance > 0.0) model_misfit_.add(normalized);
  recent_innovations_.add(normalized);
  if (options_.misfit_window > 0) {
    // prediction_scale() takes the innovation's variance to second order: near the optimum the
    // slope vanishes, and Q² still varies with the estimate's error e ~ N(0, P) through eᵀHe,
    // which adds 2 tr((HP)²) to the variance of Q² and tr((HP)²) / (2 m²) to that of z = m.
    // Without it a plant that is the twin passes audit_misfit at d ≥ 12 (its estimate errs
    // along directions the first-order slope does not see).
    const double predicted = std::max(z - residual, std::numeric_limits<double>::min());
    work_.hessian_covariance.noalias() =
        history_.hessians.middleCols(slot(history_.size - 1) * d, d) *
        estimate_.position_covariance;
    const double second_order =
        work_.hessian_covariance.cwiseProduct(work_.hessian_covariance.transpose()).sum() /
        (2.0 * predicted * predicted);
    prediction_misfit_.add(residual * residual / (variance + second_order));
    innovation_misfit_.add(residual * residual * history_.weights(slot(history_.size - 1)));
  }
  return normalized;
}

template <int N>
void ConstantVelocityEstimator<N>::fit(Index time, ChangeTest test) {
  const Index d = dimension();
  estimate_.changed = false;
  estimate_.change_ratio = std::numeric_limits<double>::quiet_NaN();
  update_fit_unit();
  shift_prior(time);
  // Warm start: the last estimate moved to `time` with its velocity.
  if (estimate_.fitted) {
    work_.start = estimate_.state;
    work_.start.head(d) += static_cast<double>(time - estimate_.time) * estimate_.state.tail(d);
  } else {
    work_.start = work_.shifted_mean;
  }
  SolveSummary best = solve(work_.start, time, work_.best);
  if (best.data_cost >
      static_cast<double>(history_.size) * options_.change_gate * options_.change_gate) {
    // The warm start explains the data badly: also try its mirror image and the prior mean.
    for (int candidate = 0; candidate < 2; ++candidate) {
      if (candidate == 0) {
        work_.start = -work_.start;
      } else {
        work_.start = work_.shifted_mean;
      }
      // Not into work_.trial: solve() uses it for its trial steps.
      const SolveSummary tried = solve(work_.start, time, work_.candidate);
      if (tried.cost < best.cost) {
        best = tried;
        work_.best = work_.candidate;
      }
    }
  }
  if (test == ChangeTest::now && history_.size > options_.change_window + 2 &&
      recent_misfit(work_.best, time, gate_unit())) {
    best = restart_from(work_.best, time);
  }
  last_solve_ = best;
  estimate_.state = work_.best;
  finish(time);
}

template <int N>
void ConstantVelocityEstimator<N>::test_change() {
  const Index time = estimate_.time;
  if (!estimate_.fitted || history_.size <= options_.change_window + 2 ||
      (!recent_misfit(estimate_.state, time, refitted_gate_unit()) && !innovations_beyond_gate())) {
    return;
  }
  last_solve_ = restart_from(estimate_.state, time);
  estimate_.state = work_.best;
  finish(time);
}

template <int N>
double ConstantVelocityEstimator<N>::normalized_residual(Index i) {
  const double residual = residual_at(i, estimate_.state, estimate_.time);
  return residual * residual * history_.weights(slot(i));
}

template <int N>
void ConstantVelocityEstimator<N>::relinearize(Index i, const QuadraticModel<N>& model,
                                               double model_variance) {
  const Index d = dimension();
  if (i < 0 || i >= history_.size) {
    throw InvalidArgumentError(
        "i",
        fmt::format("i: value is {}; rule: must lie in [0, {}) (the history)", i, history_.size));
  }
  require_dimension("model", model.dimension(), d);
  require_finite("model.center", model.center);
  require_finite("model.value", model.value);
  require_finite("model.half_gradient", model.half_gradient);
  require_finite("model.hessian", model.hessian);
  require_finite("model_variance", model_variance);
  require_non_negative("model_variance", model_variance);
  const Index s = slot(i);
  history_.controls.col(s) = history_.applied.col(s) - model.center;
  history_.values(s) = model.value;
  history_.half_gradients.col(s) = model.half_gradient;
  clip_hessian(model.hessian, s);
  history_.weights(s) = 1.0 / (measurement_variance_ + model_variance);
  history_.model_variances(s) = model_variance;
}

template <int N>
nlohmann::json ConstantVelocityEstimator<N>::save() const {
  using json_state::doubles_to_json;
  using json_state::matrix_to_json;
  using json_state::number_to_json;
  const Index d = dimension();
  nlohmann::json history = nlohmann::json::array();
  nlohmann::json hessians = nlohmann::json::array();
  for (Index i = 0; i < history_.size; ++i) {
    const Index s = slot(i);
    if (i == 0 || history_.hessians.middleCols(s * d, d) !=
                      history_.hessians.middleCols(slot(i - 1) * d, d)) {
      hessians.push_back(matrix_to_json(history_.hessians.middleCols(s * d, d)));
    }
    history.push_back({{"time", history_.times[static_cast<std::size_t>(s)]},
                       {"applied", doubles_to_json(history_.applied.col(s))},
                       {"control", doubles_to_json(history_.controls.col(s))},
                       {"value", number_to_json(history_.values(s))},
                       {"half_gradient", doubles_to_json(history_.half_gradients.col(s))},
                       {"hessian", hessians.size() - 1},
                       {"quality", number_to_json(history_.qualities(s))},
                       {"model_variance", number_to_json(history_.model_variances(s))}});
  }
  nlohmann::json snapshots = nlohmann::json::array();
  const Index kept_snapshots = std::min<Index>(fits_.count, snapshot_slots());
  for (Index i = 0; i < kept_snapshots; ++i) {
    snapshots.push_back({{"time", fits_.times[static_cast<std::size_t>(i)]},
                         {"state", doubles_to_json(fits_.states.col(i))},
                         {"covariance", matrix_to_json(fits_.covariances.middleCols(i * d, d))}});
  }
  return {
      {"format", json_format},
      {"dimension", d},
      {"max_history", options_.max_history},
      {"head", history_.head},
      {"history", std::move(history)},
      {"hessians", std::move(hessians)},
      {"last_hessian", history_.size > 0 ? matrix_to_json(last_hessian_) : nlohmann::json(nullptr)},
      {"snapshot_count", fits_.count},
      {"snapshots", std::move(snapshots)},
      {"prior_mean", doubles_to_json(prior_.mean)},
      {"prior_covariance", matrix_to_json(prior_.covariance)},
      {"prior_time", prior_.time},
      {"state", doubles_to_json(estimate_.state)},
      {"covariance", matrix_to_json(estimate_.covariance)},
      {"fit_time", estimate_.time},
      {"fitted", estimate_.fitted},
      {"changes", estimate_.changes},
      {"changed", estimate_.changed},
      {"significant", estimate_.significant},
      {"change_ratio", json_state::number_to_json(estimate_.change_ratio)},
      {"misfit", model_misfit_.save()},
      {"prediction_misfit", prediction_misfit_.save()},
      {"innovation_misfit", innovation_misfit_.save()},
      {"recent_innovations", recent_innovations_.save()}};
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
  const Index slots = snapshot_slots();
  json_state::require_header(saved, json_format, d);
  require_dimension("max_history", read_integer_field(saved, "max_history"), capacity);
  const Index head = read_integer_field(saved, "head", 0, capacity - 1);

  // The history into a copy of the ring, each entry at its slot.
  const nlohmann::json& hessians = json_state::require_array(field(saved, "hessians"), "hessians");
  const nlohmann::json& entries = json_state::require_array(field(saved, "history"), "history");
  History history = history_;
  history.head = head;
  history.size = static_cast<Index>(entries.size());
  if (history.size > capacity) {
    throw InvalidArgumentError("history",
                               fmt::format("history: has {} entries; rule: at most max_history, {}",
                                           history.size, capacity));
  }
  OffsetVector column(d);
  OffsetMatrix hessian(d, d);
  for (Index i = 0; i < history.size; ++i) {
    json_state::within(fmt::format("history[{}]", i), [&] {
      const nlohmann::json& entry = entries[static_cast<std::size_t>(i)];
      const Index at = (head + i) % capacity;
      const Index time = read_integer_field(entry, "time");
      if (i > 0 && time < history.times[static_cast<std::size_t>((head + i - 1) % capacity)]) {
        throw InvalidArgumentError(
            "time", fmt::format("time: is {}; rule: must be >= the previous entry's", time));
      }
      history.times[static_cast<std::size_t>(at)] = time;
      json_state::read_doubles(field(entry, "applied"), "applied", column);
      history.applied.col(at) = column;
      json_state::read_doubles(field(entry, "control"), "control", column);
      history.controls.col(at) = column;
      history.values(at) = read_double_field(entry, "value");
      json_state::read_doubles(field(entry, "half_gradient"), "half_gradient", column);
      history.half_gradients.col(at) = column;
      const Index which =
          read_integer_field(entry, "hessian", 0, static_cast<Index>(hessians.size()) - 1);
      json_state::read_matrix(hessians[static_cast<std::size_t>(which)],
                              fmt::format("hessians[{}]", which), hessian);
      history.hessians.middleCols(at * d, d) = hessian;
      history.qualities(at) = read_double_field(entry, "quality");
      const double model_variance = read_double_field(entry, "model_variance");
      require_non_negative("model_variance", model_variance);
      history.model_variances(at) = model_variance;
      history.weights(at) = 1.0 / (measurement_variance_ + model_variance);  // as add() forms it
    });
  }
  OffsetMatrix last_hessian = last_hessian_;
  if (history.size > 0) {
    json_state::read_matrix(field(saved, "last_hessian"), "last_hessian", last_hessian);
  }

  // The snapshots of the last snapshot_slots() assemblies fitted, at their slots.
  FitSnapshots fits = fits_;
  fits.count = read_integer_field(saved, "snapshot_count", 0);
  const nlohmann::json& snapshots = json_state::require_array(
      field(saved, "snapshots"), "snapshots", std::min(fits.count, slots));
  StateVector state_column(s);
  for (std::size_t i = 0; i < snapshots.size(); ++i) {
    json_state::within(fmt::format("snapshots[{}]", i), [&] {
      const auto at = static_cast<Index>(i);
      fits.times[i] = read_integer_field(snapshots[i], "time");
      json_state::read_doubles(field(snapshots[i], "state"), "state", state_column);
      fits.states.col(at) = state_column;
      json_state::read_matrix(field(snapshots[i], "covariance"), "covariance", hessian);
      fits.covariances.middleCols(at * d, d) = hessian;
    });
  }

  // The prior and the estimate.
  Prior prior;
  prior.mean.resize(s);
  json_state::read_doubles(field(saved, "prior_mean"), "prior_mean", prior.mean);
  prior.covariance.resize(s, s);
  json_state::read_matrix(field(saved, "prior_covariance"), "prior_covariance", prior.covariance);
  prior.time = read_integer_field(saved, "prior_time");
  Estimate estimate;
  estimate.state.resize(s);
  json_state::read_doubles(field(saved, "state"), "state", estimate.state);
  estimate.covariance.resize(s, s);
  json_state::read_matrix(field(saved, "covariance"), "covariance", estimate.covariance);
  estimate.position = estimate.state.head(d);  // as finish() forms them
  estimate.position_covariance = estimate.covariance.topLeftCorner(d, d);
  estimate.time = read_integer_field(saved, "fit_time");
  estimate.fitted = read_bool(saved, "fitted");
  estimate.changes = read_integer_field(saved, "changes", 0);
  estimate.changed = read_bool(saved, "changed");
  estimate.significant = read_bool(saved, "significant");
  estimate.change_ratio = read_double_field(saved, "change_ratio", json_state::Values::any);
  MedianMisfit misfit = model_misfit_;
  const nlohmann::json& saved_misfit = field(saved, "misfit");
  json_state::within("misfit", [&] { misfit.restore(saved_misfit); });
  MedianMisfit prediction_misfit = prediction_misfit_;
  const nlohmann::json& saved_prediction = field(saved, "prediction_misfit");
  json_state::within("prediction_misfit", [&] { prediction_misfit.restore(saved_prediction); });
  MedianMisfit innovation_misfit = innovation_misfit_;
  const nlohmann::json& saved_innovation = field(saved, "innovation_misfit");
  json_state::within("innovation_misfit", [&] { innovation_misfit.restore(saved_innovation); });
  RecentInnovations recent_innovations = recent_innovations_;
  const nlohmann::json& saved_recent = field(saved, "recent_innovations");
  json_state::within("recent_innovations", [&] { recent_innovations.restore(saved_recent); });

  // Nothing throws from here on.
  history_ = std::move(history);
  last_hessian_ = last_hessian;
  fits_ = std::move(fits);
  prior_ = std::move(prior);
  estimate_ = std::move(estimate);
  last_solve_ = SolveSummary{};
  model_misfit_ = std::move(misfit);
  prediction_misfit_ = std::move(prediction_misfit);
  innovation_misfit_ = std::move(innovation_misfit);
  recent_innovations_ = std::move(recent_innovations);
  update_fit_unit();  // as the last fit had it: it is the history's and the innovations'
}

// The run-time size: the ActiveController of the experiments, the CLI, the Python module, the
// tests, the benchmarks and the examples.
extern template class ConstantVelocityEstimator<Dynamic>;

}  // namespace twincal
