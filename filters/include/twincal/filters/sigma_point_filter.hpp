#pragma once
/// @file
/// `SigmaPointFilter<StateModel, MeasurementModel, Scheme>`: the sigma-point Kalman filter of the
/// paper's Sec. 2.3.1 for the state-space model (5b)–(5c): the offset state δu, a scalar black-box
/// measurement whose inputs (assembly x_t, control u_t) arrive at update time, and the Gaussian
/// posterior N(δû_t, P_t) of eq. (8). The scheme (a member policy) makes it a UKF
/// (MerweScaledSigmaPoints: the sigma points S_t and weights W(s_t) of eq. (11)), a CKF
/// (SphericalRadialSigmaPoints) or anything else that satisfies SigmaPointScheme.
///
/// predict (Q = Σu for the random walk of eq. (5c)):
///   χ_i* = f(χ_i),  x⁻ = Σ Wm_i χ_i*,  P⁻ = Σ Wc_i (χ_i* − x⁻)(χ_i* − x⁻)ᵀ + Q,
///   then the update points are redrawn from (x⁻, P⁻) or are the χ_i* (SigmaPointRefresh).
/// update with z (measurement model (5b), R = σz²):
///   γ_i = h(χ_i; x_t, u_t),  ẑ = Σ Wm_i γ_i,  S = Σ Wc_i (γ_i − ẑ)² + R,
///   Pxz = Σ Wc_i (χ_i − x⁻)(γ_i − ẑ),  K = Pxz/S,  x⁺ = x⁻ + K (z − ẑ),  P⁺ = P⁻ − K S Kᵀ.
///
/// `update(z, inputs)` is `commit(preview(inputs), z)`: the preview computes everything that does
/// not depend on z (one batch of measurement evaluations, P⁺, its factor), so a controller can
/// preview many candidate controls and commit the chosen one without evaluating h again. The
/// preview's P⁺ for a candidate u_t is the P_{t+1}(u_t) of the exploration loss, eq. (12).
///
/// Errors: bad arguments, non-finite model outputs, a non-finite z and failed factorizations throw
/// typed twincal errors before the filter's state changes (strong guarantee).
///
/// Allocation: predict and update work in buffers sized at construction, so a step allocates
/// nothing at any size, Dynamic included (the first update sizes the kept preview; the error
/// paths, covariance repairs and the Joseph form at Dynamic sizes aside). preview(inputs) returns
/// a new Preview; preview(inputs, out) reuses one.

#include <algorithm>
#include <cstdint>
#include <string>
#include <string_view>
#include <utility>

#include <fmt/format.h>
#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "twincal/core/cholesky.hpp"
#include "twincal/core/eigen.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/options.hpp"
#include "twincal/core/symmetrize.hpp"
#include "twincal/core/validate.hpp"
#include "twincal/filters/filter_state_json.hpp"
#include "twincal/filters/measurement_model.hpp"
#include "twincal/filters/measurement_preview.hpp"
#include "twincal/filters/sigma_point_filter_options.hpp"
#include "twincal/filters/sigma_point_scheme.hpp"
#include "twincal/filters/state_model.hpp"
#include "twincal/filters/unscented_transform.hpp"

namespace twincal {

/// The quantities of the last committed update (all zero before the first).
template <int N>
struct UpdateRecord {
  double innovation = 0.0;           ///< y = z − ẑ
  double innovation_variance = 0.0;  ///< S
  Vector<N> gain;                    ///< K

  /// log N(y; 0, S), 0 before the first update. Computed on request: a logarithm per step is a
  /// visible share of a small filter's step, and most runs never read it.
  [[nodiscard]] double log_likelihood() const noexcept {
    return innovation_variance > 0.0 ? innovation_log_likelihood(innovation, innovation_variance)
                                     : 0.0;
  }
};

template <StateModel SM, MeasurementModel MM, SigmaPointScheme Scheme>
requires(SM::dimension_at_compile_time == MM::dimension_at_compile_time) class SigmaPointFilter {
 public:
  static constexpr int dimension_at_compile_time = SM::dimension_at_compile_time;
  static constexpr int points_at_compile_time =
      Scheme::points_at_compile_time(dimension_at_compile_time);
  using StateVector = Vector<dimension_at_compile_time>;
  using CovarianceMatrix = SquareMatrix<dimension_at_compile_time>;
  using PointMatrix = Matrix<dimension_at_compile_time, points_at_compile_time>;
  using WeightVector = Vector<points_at_compile_time>;
  using Inputs = typename MM::Inputs;
  using Preview = MeasurementPreview<dimension_at_compile_time, points_at_compile_time>;
  using Record = UpdateRecord<dimension_at_compile_time>;

  static constexpr std::string_view json_format = "twincal.sigma_point_filter";

  /// Starts from N(initial_state, initial_covariance).
  /// @throws InvalidArgumentError (options; the scheme does not admit the dimension; R <= 0),
  ///         DimensionMismatchError, NonFiniteError, NotPositiveDefiniteError (P0 not symmetric
  ///         positive definite and the repair policy does not fix it).
  SigmaPointFilter(SM state_model, MM measurement_model, Scheme scheme,
                   const StateVector& initial_state, const CovarianceMatrix& initial_covariance,
                   SigmaPointFilterOptions options = {})
      : state_model_(std::move(state_model)),
        measurement_model_(std::move(measurement_model)),
        scheme_(std::move(scheme)),
        options_(options) {
    require_valid("options", options_);
    const Index n = state_model_.dimension();
    if constexpr (dimension_at_compile_time != Dynamic) {
      require_dimension("state_model.dimension()", n, dimension_at_compile_time);
    }
    if constexpr (requires { measurement_model_.dimension(); }) {
      require_dimension("measurement_model.dimension()", measurement_model_.dimension(), n);
    }
    require_dimension("initial_state", initial_state.size(), n);
    require_finite("initial_state", initial_state);
    require_shape("initial_covariance", initial_covariance, n, n);
    require_symmetric("initial_covariance", initial_covariance);
    require_shape("process_noise", state_model_.process_noise(), n, n);
    require_finite("process_noise", state_model_.process_noise());
    require_finite("noise_variance", measurement_model_.noise_variance());
    require_positive("noise_variance", measurement_model_.noise_variance());

    const Index m = scheme_.num_points(n);
    mean_weights_.resize(m);
    covariance_weights_.resize(m);
    scheme_.weights(n, mean_weights_, covariance_weights_);

    x_ = initial_state;
    P_ = initial_covariance;
    points_.resize(n, m);
    workspace_.resize(n, m);
    draw_points(x_, P_, "initial_covariance");
    last_update_.gain = StateVector::Zero(n);
  }

  // --- the filter --------------------------------------------------------------------------

  /// Time update: propagates the sigma points through f and forms (x⁻, P⁻) with Q added.
  /// @throws NonFiniteError (f or Q not finite), DimensionMismatchError (Q's shape),
  ///         NotPositiveDefiniteError (redraw: P⁻ cannot be factored under the repair policy).
  void predict() {
    const Index n = dimension();
    const auto& process_noise = state_model_.process_noise();
    require_shape("process_noise", process_noise, n, n);
    require_finite("process_noise", process_noise);

    // Into the workspace first: the state changes only once nothing can throw.
    Workspace& w = workspace_;
    propagate_points(state_model_, points_, w.propagated, w.state);
    weighted_mean(w.propagated, mean_weights_, w.mean);
    weighted_covariance(w.propagated, covariance_weights_, w.mean, w.centred, w.weighted,
                        w.covariance);
    w.covariance += process_noise;
    if (options_.symmetrize) symmetrize(w.covariance);

    if (options_.refresh == SigmaPointRefresh::redraw) {
      draw_points(w.mean, w.covariance, "prior covariance");
    } else {
      points_.swap(w.propagated);
    }
    x_.swap(w.mean);
    P_.swap(w.covariance);
    ++revision_;
  }

  /// The update for `inputs` without committing it: evaluates h at the current sigma points
  /// (one batch call when the model has `measure_batch`), then `preview(values)`.
  /// @throws as the measurement model and `preview(values)`.
  [[nodiscard]] Preview preview(const Inputs& inputs) const {
    Preview p;
    preview(inputs, p);
    return p;
  }

  /// preview(inputs) into `out`: allocates nothing, at any size, once `out` holds a preview of
  /// this filter (and the measurement model allocates nothing) — the form for loops over many
  /// candidate inputs. @throws as preview(inputs); `out` is then unspecified.
  void preview(const Inputs& inputs, Preview& out) const {
    out.measurements.resize(num_points());
    evaluate_measurements(measurement_model_, points_, inputs, out.measurements);
    JosephScratch scratch;
    fill_preview(out.measurements, out, scratch);
  }

  /// The update given the measurement values γ_i = h(χ_i) at `sigma_points()` (e.g. from a
  /// controller's batch over several candidate controls): ẑ, S, Pxz, K and P⁺ with its factor.
  /// @throws DimensionMismatchError, NonFiniteError (a value), NotPositiveDefiniteError (S <= 0,
  ///         or P⁺ cannot be factored under the repair policy).
  template <typename Derived>
  [[nodiscard]] Preview preview(const Eigen::MatrixBase<Derived>& values) const {
    Preview p;
    JosephScratch scratch;
    fill_preview(values, p, scratch);
    return p;
  }

  /// preview(values) into `out`: allocates nothing once `out` holds a preview of this filter.
  /// @throws as preview(values); `out` is then unspecified.
  template <typename Derived>
  void preview(const Eigen::MatrixBase<Derived>& values, Preview& out) const {
    JosephScratch scratch;
    fill_preview(values, out, scratch);
  }

  /// Completes a previewed update with the measurement z: x⁺ = x⁻ + K (z − ẑ), P⁺ from the
  /// preview, new sigma points from (x⁺, L⁺). Evaluates nothing.
  /// @throws InvalidArgumentError (the preview is not of the current state), NonFiniteError (z).
  void commit(const Preview& preview, double z) {
    if (preview.revision != revision_) {
      throw InvalidArgumentError(
          "preview", fmt::format("preview: was computed at filter revision {}, the filter is at "
                                 "revision {}; rule: commit only a preview of the current state "
                                 "(predict, commit and restore invalidate previews)",
                                 preview.revision, revision_));
    }
    require_finite("z", z);
    const double innovation = z - preview.predicted_measurement;
    StateVector& posterior_mean = workspace_.mean;
    posterior_mean = x_;
    posterior_mean.noalias() += preview.gain * innovation;
    require_finite("posterior state", posterior_mean);

    x_.swap(posterior_mean);
    P_ = preview.posterior_covariance;
    scheme_.generate(x_, preview.posterior_factor, points_);
    last_update_.innovation = innovation;
    last_update_.innovation_variance = preview.innovation_variance;
    last_update_.gain = preview.gain;
    ++revision_;
    ++updates_;
  }

  /// Measurement update with z for `inputs`: `commit(preview(inputs), z)`, through a preview
  /// kept by the filter (no allocation per step after the first, at any size).
  void update(double z, const Inputs& inputs) {
    require_finite("z", z);  // before spending evaluations on a measurement that cannot be used
    Preview& p = workspace_.preview;
    p.measurements.resize(num_points());
    evaluate_measurements(measurement_model_, points_, inputs, p.measurements);
    fill_preview(p.measurements, p, workspace_.joseph);
    commit(p, z);
  }

  // --- state ---------------------------------------------------------------------------------

  [[nodiscard]] Index dimension() const noexcept { return x_.size(); }
  [[nodiscard]] Index num_points() const noexcept { return mean_weights_.size(); }
  /// The mean: x⁻ after predict, x⁺ after update.
  [[nodiscard]] const StateVector& state() const noexcept { return x_; }
  /// The covariance: P⁻ after predict, P⁺ after update.
  [[nodiscard]] const CovarianceMatrix& covariance() const noexcept { return P_; }
  /// The points the next update evaluates h at (n × M, one per column).
  [[nodiscard]] const PointMatrix& sigma_points() const noexcept { return points_; }
  [[nodiscard]] const WeightVector& mean_weights() const noexcept { return mean_weights_; }
  [[nodiscard]] const WeightVector& covariance_weights() const noexcept {
    return covariance_weights_;
  }
  [[nodiscard]] const Record& last_update() const noexcept { return last_update_; }
  /// Number of committed updates (the filter's step count).
  [[nodiscard]] std::uint64_t update_count() const noexcept { return updates_; }
  /// Changes with every predict, commit and restore; previews carry it.
  [[nodiscard]] std::uint64_t revision() const noexcept { return revision_; }
  [[nodiscard]] const SigmaPointFilterOptions& options() const noexcept { return options_; }
  [[nodiscard]] const SM& state_model() const noexcept { return state_model_; }
  [[nodiscard]] const MM& measurement_model() const noexcept { return measurement_model_; }
  [[nodiscard]] const Scheme& scheme() const noexcept { return scheme_; }

  // --- save / restore ------------------------------------------------------------------------

  /// x, P, the update count and the current sigma points (which, after a predict with
  /// reuse_propagated, are not a function of x and P) as JSON; restores bit-exactly.
  [[nodiscard]] nlohmann::json save() const {
    nlohmann::json saved;
    saved["format"] = json_format;
    saved["dimension"] = dimension();
    saved["updates"] = updates_;
    saved["state"] = json_state::vector_to_json(x_);
    saved["covariance"] = json_state::columns_to_json(P_);
    saved["sigma_points"] = json_state::columns_to_json(points_);
    return saved;
  }

  /// Restores a state written by `save()` of a filter of the same dimension and scheme.
  /// Invalidates previews.
  /// @throws InvalidArgumentError (malformed or foreign JSON), DimensionMismatchError,
  ///         NonFiniteError, NotPositiveDefiniteError (the covariance) — the filter unchanged.
  void restore(const nlohmann::json& saved) {
    const Index n = dimension();
    json_state::require_header(saved, json_format, n);
    const std::uint64_t updates = json_state::read_count(saved, "updates");
    StateVector x(n);
    json_state::read_vector(json_state::field(saved, "state"), "state", x);
    CovarianceMatrix p(n, n);
    json_state::read_columns(json_state::field(saved, "covariance"), "covariance", p);
    // Round-off asymmetry of a filterpy-style P − K S Kᵀ is legitimate state.
    require_positive_definite("covariance", p, /*allow_semidefinite=*/false,
                              /*symmetry_tolerance=*/1e-9);
    PointMatrix points(n, num_points());
    json_state::read_columns(json_state::field(saved, "sigma_points"), "sigma_points", points);

    x_ = x;
    P_ = p;
    points_ = points;
    updates_ = updates;
    last_update_ = Record{0.0, 0.0, StateVector::Zero(n)};
    ++revision_;
  }

 private:
  // Buffers of the Joseph-form posterior, sized when first used: the update's are kept in the
  // workspace, a const preview's are its own (empty, so free, unless the Joseph form is on).
  struct JosephScratch {
    void resize(Index n) {
      factor.resize(n, n);
      linearisation.resize(n);
      transition.resize(n, n);
      product.resize(n, n);
    }
    CovarianceMatrix factor;
    StateVector linearisation;
    CovarianceMatrix transition;
    CovarianceMatrix product;
  };

  // Buffers of predict and update, sized at construction: reused, they make the steps
  // allocation-free at Dynamic sizes too. Not state: copies and restore() need not match them.
  struct Workspace {
    void resize(Index n, Index m) {
      propagated.resize(n, m);
      centred.resize(n, m);
      weighted.resize(n, m);
      state.resize(n);
      mean.resize(n);
      covariance.resize(n, n);
      factor.resize(n, n);
      joseph.resize(n);
    }
    PointMatrix propagated;
    PointMatrix centred;
    PointMatrix weighted;
    StateVector state;
    StateVector mean;
    CovarianceMatrix covariance;
    CovarianceMatrix factor;
    JosephScratch joseph;
    Preview preview;
  };

  // Factors `covariance` into the workspace's factor (repairing it per the options, in which
  // case the repaired matrix replaces it), then writes the scheme's points for (mean, L) into
  // points_ — only once the factorization has succeeded.
  void draw_points(const StateVector& mean, CovarianceMatrix& covariance, std::string_view name) {
    detail::cholesky_into_validated(covariance, workspace_.factor, options_.factorization, name);
    scheme_.generate(mean, workspace_.factor, points_);
  }

  // The z-independent update for `values` (may be p.measurements itself) into `p`, with `s`
  // as the Joseph form's scratch.
  template <typename Derived>
  void fill_preview(const Eigen::MatrixBase<Derived>& values, Preview& p, JosephScratch& s) const {
    measurement_statistics(points_, x_, mean_weights_, covariance_weights_, values,
                           measurement_model_.noise_variance(), p);
    if (options_.joseph_form) {
      joseph_posterior(p, s);
    } else {
      p.posterior_covariance = P_;
      p.posterior_covariance.noalias() -= p.gain * (p.innovation_variance * p.gain.transpose());
    }
    if (options_.symmetrize) symmetrize(p.posterior_covariance);
    p.factorization = detail::cholesky_into_validated(
        p.posterior_covariance, p.posterior_factor, options_.factorization, "posterior covariance");
    p.revision = revision_;
  }

  // Joseph form with the statistically linearised measurement H = P⁻¹ Pxz (see
  // SigmaPointFilterOptions::joseph_form), into p.posterior_covariance; allocates nothing once
  // `s` is sized (P⁻ is factored in s.factor's own storage).
  void joseph_posterior(Preview& p, JosephScratch& s) const {
    s.resize(dimension());
    s.factor = P_;
    const Eigen::LLT<Eigen::Ref<CovarianceMatrix>> llt(s.factor);
    if (llt.info() != Eigen::Success) {
      const double lambda_min = smallest_eigenvalue(P_);
      throw NotPositiveDefiniteError(
          "covariance",
          fmt::format("covariance: the Joseph-form update needs P⁻¹ but P has "
                      "smallest eigenvalue {:.6g}; rule: must be positive definite",
                      lambda_min),
          lambda_min);
    }
    s.linearisation = p.cross_covariance;
    llt.solveInPlace(s.linearisation);
    const double linearisation_error =
        p.measurement_variance - p.cross_covariance.dot(s.linearisation);
    const double effective_noise =
        measurement_model_.noise_variance() + std::max(linearisation_error, 0.0);
    s.transition.setIdentity();
    s.transition.noalias() -= p.gain * s.linearisation.transpose();
    s.product.noalias() = s.transition * P_;
    p.posterior_covariance.noalias() = s.product * s.transition.transpose();
    p.posterior_covariance.noalias() += effective_noise * (p.gain * p.gain.transpose());
  }

  SM state_model_;
  MM measurement_model_;
  Scheme scheme_;
  SigmaPointFilterOptions options_;
  WeightVector mean_weights_;
  WeightVector covariance_weights_;
  StateVector x_;
  CovarianceMatrix P_;
  PointMatrix points_;
  Record last_update_;
  Workspace workspace_;
  std::uint64_t updates_ = 0;
  std::uint64_t revision_ = 0;
};

}  // namespace twincal
