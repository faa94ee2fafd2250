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
///
/// Structure: what does not depend on how the covariance is kept (the models, the scheme, the
/// mean, the points, preview/commit, save/restore) is SigmaPointFilterCore, shared with
/// SquareRootSigmaPointFilter; this filter holds one with the policy StandardCovariance (P itself,
/// below) as its covariance form.

#include <algorithm>
#include <cstdint>
#include <string_view>
#include <utility>

#include <fmt/format.h>
#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "twincal/core/cholesky.hpp"
#include "twincal/core/eigen.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/symmetrize.hpp"
#include "twincal/core/validate.hpp"
#include "twincal/filters/filter_state_json.hpp"
#include "twincal/filters/measurement_model.hpp"
#include "twincal/filters/measurement_preview.hpp"
#include "twincal/filters/sigma_point_filter_core.hpp"
#include "twincal/filters/sigma_point_filter_options.hpp"
#include "twincal/filters/sigma_point_scheme.hpp"
#include "twincal/filters/state_model.hpp"
#include "twincal/filters/unscented_transform.hpp"

namespace twincal {

/// The covariance form (CovarianceForm) of SigmaPointFilter: keeps P itself.
/// P⁻ = Σ Wc_i (χ_i* − x⁻)(χ_i* − x⁻)ᵀ + Q; P⁺ = P⁻ − K S Kᵀ, or in Joseph form (options);
/// P⁺ is factored (repaired per the options) for the next points.
template <int N, int M>
class StandardCovariance {
 public:
  using Options = SigmaPointFilterOptions;
  using Initial = SquareMatrix<N>;
  using CovarianceMatrix = SquareMatrix<N>;
  using StateVector = Vector<N>;
  using PointMatrix = Matrix<N, M>;
  using WeightVector = Vector<M>;
  using Preview = MeasurementPreview<N, M>;

  static constexpr const char* json_field = "covariance";

  // The n × M buffers of the predicted covariance.
  struct PointBuffers {
    void resize(Index n, Index m) {
      centred.resize(n, m);
      weighted.resize(n, m);
    }
    PointMatrix centred;
    PointMatrix weighted;
  };

  // P⁻ and its factor (the points are drawn from it).
  struct FactorBuffers {
    void resize(Index n, Index /*m*/) {
      covariance.resize(n, n);
      factor.resize(n, n);
    }
    CovarianceMatrix covariance;
    CovarianceMatrix factor;
  };

  // Buffers of the Joseph-form posterior, sized when first used: the update's are kept by the
  // core, a const preview's are its own (empty, so free, unless the Joseph form is on).
  struct Scratch {
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

  struct Cache {};

  [[nodiscard]] const CovarianceMatrix& covariance() const noexcept { return P_; }

  static void require_initial(const Initial& initial_covariance, Index n) {
    require_shape("initial_covariance", initial_covariance, n, n);
    require_symmetric("initial_covariance", initial_covariance);
  }

  // P0, factored (and repaired per the options, the repaired matrix replacing it).
  template <typename Workspace>
  [[nodiscard]] const CovarianceMatrix& start(const Options& options,
                                              const Initial& initial_covariance, Workspace& w) {
    P_ = initial_covariance;
    detail::cholesky_into_validated(P_, w.factor.factor, options.factorization,
                                    "initial_covariance");
    return w.factor.factor;
  }

  // P⁻ into w.factor, and its factor when the points are redrawn (a repaired P⁻ replaces the
  // computed one, so that P and its points agree).
  template <typename Workspace, EigenMatrixOfShape<N, N> Noise>
  void predict(const Options& options, Workspace& w, const WeightVector& covariance_weights,
               const Noise& process_noise, bool factor) const {
    weighted_covariance(w.propagated, covariance_weights, w.mean, w.points.centred,
                        w.points.weighted, w.factor.covariance);
    w.factor.covariance += process_noise;
    if (options.symmetrize) symmetrize(w.factor.covariance);
    if (factor) {
      detail::cholesky_into_validated(w.factor.covariance, w.factor.factor, options.factorization,
                                      "prior covariance");
    }
  }
  template <typename Workspace>
  [[nodiscard]] const CovarianceMatrix& prior_factor(const Workspace& w) const noexcept {
    return w.factor.factor;
  }
  template <typename Workspace>
  void accept_prior(Workspace& w) noexcept {
    P_.swap(w.factor.covariance);
  }

  // A const preview's scratch stays empty: the Joseph form sizes it when used.
  void prepare(Scratch& /*scratch*/, Index /*n*/) const noexcept {}

  // P⁺ (always: it is what the standard form computes) and its factor.
  void posterior(const Options& options, Preview& p, Scratch& s, double noise_variance,
                 bool /*report*/) const {
    if (options.joseph_form) {
      joseph_posterior(p, s, noise_variance);
    } else {
      p.posterior_covariance = P_;
      p.posterior_covariance.noalias() -= p.gain * (p.innovation_variance * p.gain.transpose());
    }
    if (options.symmetrize) symmetrize(p.posterior_covariance);
    p.factorization = detail::cholesky_into_validated(
        p.posterior_covariance, p.posterior_factor, options.factorization, "posterior covariance");
  }
  void accept_posterior(const Preview& p) { P_ = p.posterior_covariance; }

  [[nodiscard]] const CovarianceMatrix& stored() const noexcept { return P_; }
  [[nodiscard]] static CovarianceMatrix read(const nlohmann::json& saved, Index n) {
    CovarianceMatrix p(n, n);
    json_state::read_columns(json_state::field(saved, "covariance"), "covariance", p);
    // Round-off asymmetry of a filterpy-style P − K S Kᵀ is legitimate state.
    require_positive_definite("covariance", p, /*allow_semidefinite=*/false,
                              /*symmetry_tolerance=*/1e-9);
    return p;
  }
  void assign(CovarianceMatrix value) { P_ = std::move(value); }

 private:
  // Joseph form with the statistically linearised measurement H = P⁻¹ Pxz (see
  // SigmaPointFilterOptions::joseph_form), into p.posterior_covariance; allocates nothing once
  // `s` is sized (P⁻ is factored in s.factor's own storage).
  void joseph_posterior(Preview& p, Scratch& s, double noise_variance) const {
    s.resize(P_.rows());
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
    const double effective_noise = noise_variance + std::max(linearisation_error, 0.0);
    s.transition.setIdentity();
    s.transition.noalias() -= p.gain * s.linearisation.transpose();
    s.product.noalias() = s.transition * P_;
    p.posterior_covariance.noalias() = s.product * s.transition.transpose();
    p.posterior_covariance.noalias() += effective_noise * (p.gain * p.gain.transpose());
  }

  CovarianceMatrix P_;
};

template <StateModel SM, MeasurementModel MM, SigmaPointScheme Scheme>
requires(SM::dimension_at_compile_time == MM::dimension_at_compile_time) class SigmaPointFilter {
  using Core = SigmaPointFilterCore<SM, MM, Scheme, StandardCovariance>;

 public:
  static constexpr int dimension_at_compile_time = Core::dimension_at_compile_time;
  static constexpr int points_at_compile_time = Core::points_at_compile_time;
  using StateVector = typename Core::StateVector;
  using CovarianceMatrix = typename Core::CovarianceMatrix;
  using PointMatrix = typename Core::PointMatrix;
  using WeightVector = typename Core::WeightVector;
  using Inputs = typename Core::Inputs;
  using Preview = typename Core::Preview;
  using Record = typename Core::Record;

  static constexpr std::string_view json_format = "twincal.sigma_point_filter";

  /// Starts from N(initial_state, initial_covariance).
  /// @throws InvalidArgumentError (options; the scheme does not admit the dimension; R <= 0),
  ///         DimensionMismatchError, NonFiniteError, NotPositiveDefiniteError (P0 not symmetric
  ///         positive definite and the repair policy does not fix it).
  SigmaPointFilter(SM state_model, MM measurement_model, Scheme scheme,
                   const StateVector& initial_state, const CovarianceMatrix& initial_covariance,
                   SigmaPointFilterOptions options = {})
      : core_(std::move(state_model), std::move(measurement_model), std::move(scheme),
              initial_state, initial_covariance, options) {}

  // --- the filter --------------------------------------------------------------------------

  /// Time update: propagates the sigma points through f and forms (x⁻, P⁻) with Q added.
  /// @throws NonFiniteError (f or Q not finite), DimensionMismatchError (Q's shape),
  ///         NotPositiveDefiniteError (redraw: P⁻ cannot be factored under the repair policy).
  void predict() { core_.predict(); }

  /// The update for `inputs` without committing it: evaluates h at the current sigma points
  /// (one batch call when the model has `measure_batch`), then `preview(values)`.
  /// @throws as the measurement model and `preview(values)`.
  [[nodiscard]] Preview preview(const Inputs& inputs) const { return core_.preview(inputs); }

  /// preview(inputs) into `out`: allocates nothing, at any size, once `out` holds a preview of
  /// this filter (and the measurement model allocates nothing) — the form for loops over many
  /// candidate inputs. @throws as preview(inputs); `out` is then unspecified.
  void preview(const Inputs& inputs, Preview& out) const { core_.preview(inputs, out); }

  /// The update given the measurement values γ_i = h(χ_i) at `sigma_points()` (e.g. from a
  /// controller's batch over several candidate controls): ẑ, S, Pxz, K and P⁺ with its factor.
  /// @throws DimensionMismatchError, NonFiniteError (a value), NotPositiveDefiniteError (S <= 0,
  ///         or P⁺ cannot be factored under the repair policy).
  template <typename Derived>
  [[nodiscard]] Preview preview(const Eigen::MatrixBase<Derived>& values) const {
    return core_.preview(values);
  }

  /// preview(values) into `out`: allocates nothing once `out` holds a preview of this filter.
  /// @throws as preview(values); `out` is then unspecified.
  template <typename Derived>
  void preview(const Eigen::MatrixBase<Derived>& values, Preview& out) const {
    core_.preview(values, out);
  }

  /// Completes a previewed update with the measurement z: x⁺ = x⁻ + K (z − ẑ), P⁺ from the
  /// preview, new sigma points from (x⁺, L⁺). Evaluates nothing.
  /// @throws InvalidArgumentError (the preview is not of the current state), NonFiniteError (z).
  void commit(const Preview& preview, double z) { core_.commit(preview, z); }

  /// Measurement update with z for `inputs`: `commit(preview(inputs), z)`, through a preview
  /// kept by the filter (no allocation per step after the first, at any size).
  void update(double z, const Inputs& inputs) { core_.update(z, inputs); }

  // --- state ---------------------------------------------------------------------------------

  [[nodiscard]] Index dimension() const noexcept { return core_.dimension(); }
  [[nodiscard]] Index num_points() const noexcept { return core_.num_points(); }
  /// The mean: x⁻ after predict, x⁺ after update.
  [[nodiscard]] const StateVector& state() const noexcept { return core_.state(); }
  /// The covariance: P⁻ after predict, P⁺ after update.
  [[nodiscard]] const CovarianceMatrix& covariance() const noexcept {
    return core_.form().covariance();
  }
  /// The points the next update evaluates h at (n × M, one per column).
  [[nodiscard]] const PointMatrix& sigma_points() const noexcept { return core_.sigma_points(); }
  [[nodiscard]] const WeightVector& mean_weights() const noexcept { return core_.mean_weights(); }
  [[nodiscard]] const WeightVector& covariance_weights() const noexcept {
    return core_.covariance_weights();
  }
  [[nodiscard]] const Record& last_update() const noexcept { return core_.last_update(); }
  /// Number of committed updates (the filter's step count).
  [[nodiscard]] std::uint64_t update_count() const noexcept { return core_.update_count(); }
  /// Changes with every predict, commit and restore; previews carry it.
  [[nodiscard]] std::uint64_t revision() const noexcept { return core_.revision(); }
  [[nodiscard]] const SigmaPointFilterOptions& options() const noexcept { return core_.options(); }
  [[nodiscard]] const SM& state_model() const noexcept { return core_.state_model(); }
  [[nodiscard]] const MM& measurement_model() const noexcept { return core_.measurement_model(); }
  [[nodiscard]] const Scheme& scheme() const noexcept { return core_.scheme(); }

  // --- save / restore ------------------------------------------------------------------------

  /// x, P, the update count and the current sigma points (which, after a predict with
  /// reuse_propagated, are not a function of x and P) as JSON; restores bit-exactly.
  [[nodiscard]] nlohmann::json save() const { return core_.save(json_format); }

  /// Restores a state written by `save()` of a filter of the same dimension and scheme.
  /// Invalidates previews.
  /// @throws InvalidArgumentError (malformed or foreign JSON), DimensionMismatchError,
  ///         NonFiniteError, NotPositiveDefiniteError (the covariance) — the filter unchanged.
  void restore(const nlohmann::json& saved) { core_.restore(saved, json_format); }

 private:
  Core core_;
};

}  // namespace twincal
