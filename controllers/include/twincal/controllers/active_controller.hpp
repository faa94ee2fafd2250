#pragma once
/// @file
/// `ActiveCalibrationController<Twin, N, Probe, Scheme, Optimizer>` and its preset
/// `ActiveController<Twin, N>` (presets.hpp): a controller that tracks the offset δu* of every
/// locator at once and whose cost grows polynomially in d (docs/controllers.md, "Beyond the
/// paper"). Per assembly x_t:
///   1. u0(x_t), z*(x_t) (eq. 3);
///   2. the twin's local model Q²(x_t, v) ≈ c + 2gᵀ(v − u0) + (v − u0)ᵀH(v − u0)
///      (QuadraticSurrogate: d + 1 evaluations, (d + 1)(d + 2)/2 when H is refitted), checked
///      against the twin at two points where it is about to be used;
///   3. the estimate δû_t and its covariance P: while the model holds, from the moving-horizon
///      estimator of a drifting offset (ConstantVelocityEstimator: the maximum a posteriori
///      offset and velocity over the assemblies measured so far, each under its own model, with
///      changes of velocity detected); otherwise from a random-walk filter (eq. 5c) updated with
///      sigma points of the Scheme policy;
///   4. a known probe p (the Probe policy, ThompsonProbe by default: a draw from N(0, s²P); p = 0
///      without a model that passed its check) and u_t = clip(u0 + p) + clamp(δû): the twin's
///      locator bounds hold in the twin's frame (u_t − δû), and the correction is at most
///      ActiveOptions::max_offset_fraction of the box width, so a twin optimum at its bound can
///      be corrected and a lost estimate cannot drive the fixture far outside its range (an
///      estimate beyond that reach is not applied: ActiveOptions::clamp_beyond_reach); right
///      after a surprise (a z the estimate neither predicted nor explains once refitted) it
///      moves at most ActiveOptions::surprise_step_fraction of the box from the last one applied
///      (always, with correction_step_fraction), and after hold_after_surprises such surprises
///      within a few assemblies it is not applied, nor after one among the episode's first
///      (trial_innovations), after which the correction is also audited (audit_after_failed_trial);
///   5. observe: z_t joins the estimator's history (or updates the random-walk filter, with an
///      innovation gate that inflates an overconfident P, process noise adapted to the
///      normalized innovations, and a floor and a ceiling on P's eigenvalues).
/// Where Q² is not a quadratic (the model fails its check), four more rules hold: each
/// assembly's residual is weighed by its model's error (ActiveOptions::weigh_model_error); the
/// models of earlier assemblies are refitted where the fit now uses them
/// (relinearization_budget, relinearization_reach); the probe is priced by the regret the plant
/// shows rather than by P alone, and the model is fitted where that probe puts the plant
/// (regret_probe); and the correction is audited against u0 on the plant's own answers
/// (audit_period) — do no harm.
/// Twin evaluations per assembly: d + 3 (model and check), (d + 1)(d + 2)/2 + 2 on a refit of H
/// (3 and 2d + 3 where the model comes from the key points' deviations), plus up to
/// relinearization_budget · (d + 1)² (2 (d + 1)² by default) for refits of earlier models, plus
/// the sigma points in the fallback — O(d²), against the paper's O(2^d) candidates × sigma points.
///
/// Failure policy: when fitting or checking the model fails (a twin error, a non-finite value),
/// the assembly runs in the sigma-point mode with p = 0, and last_proposal().fallback says why
/// (after a TwinError the model is tried again at the next assembly, else after quadratic_retry);
/// the estimate is not touched before observe. When the twin fails (TwinError) in the
/// sigma-point update, observe drops z — the estimate stays as predicted, as a filter's does
/// without a measurement — and last_proposal().dropped_measurement says why. Non-finite z is
/// refused by observe (NonFiniteError) with the state unchanged.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <limits>
#include <optional>
#include <string_view>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <nlohmann/json.hpp>

#include "twincal/controllers/active/active_options.hpp"
#include "twincal/controllers/active/active_step_report.hpp"
#include "twincal/controllers/active/constant_velocity_estimator.hpp"
#include "twincal/controllers/active/do_no_harm_audit.hpp"
#include "twincal/controllers/active/probe_design.hpp"
#include "twincal/controllers/active/quadratic_model.hpp"
#include "twincal/controllers/active/quadratic_surrogate.hpp"
#include "twincal/controllers/active/thompson_probe.hpp"
#include "twincal/controllers/controller.hpp"
#include "twincal/controllers/controller_state_json.hpp"
#include "twincal/controllers/individual_optimum.hpp"
#include "twincal/controllers/nlopt_optimizer.hpp"
#include "twincal/controllers/optimizer.hpp"
#include "twincal/controllers/proposal_report.hpp"
#include "twincal/core/cholesky.hpp"
#include "twincal/core/eigen.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/median.hpp"
#include "twincal/core/options.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/core/symmetrize.hpp"
#include "twincal/core/validate.hpp"
#include "twincal/filters/measurement_preview.hpp"
#include "twincal/filters/sigma_point_scheme.hpp"
#include "twincal/filters/spherical_radial_sigma_points.hpp"
#include "twincal/filters/unscented_transform.hpp"
#include "twincal/models/kept_assemblies.hpp"
#include "twincal/models/twin.hpp"

namespace twincal {

template <Twin T, int N = Dynamic, typename Probe = ThompsonProbe<N>,
          SigmaPointScheme Scheme = SphericalRadialSigmaPoints, Optimizer O = NloptOptimizer>
requires ProbeDesign<Probe, N>
class ActiveCalibrationController {
 public:
  static constexpr int dimension_at_compile_time = N;
  using Twin = T;
  using Assembly = typename T::Assembly;
  using ControlVector = Vector<N>;
  using CovarianceMatrix = SquareMatrix<N>;

  /// Starts from δû0 ~ N(0, initial_variance·I), drawn from `stream.substream("initial_offset")`
  /// (as the paper's filters are, so controllers built from one stream start alike); the
  /// estimator's prior is centred there with the spread of options.trajectory, the random-walk
  /// filter's P0 = initial_variance·I. A probe with reseed() draws from stream.substream("probe").
  /// Refers to `twin`, which must outlive the controller.
  /// @throws InvalidArgumentError (options, the twin's box), DimensionMismatchError (N and the
  ///         twin's d).
  ActiveCalibrationController(const T& twin, const RandomStream& stream, ActiveOptions options = {},
                              Probe probe = {}, Scheme scheme = {}, O optimizer = O{})
      : twin_(&twin),
        options_((require_valid("ActiveOptions", options), options)),
        optimum_(twin, std::move(optimizer)),
        surrogate_(twin, options_.surrogate),
        probe_(std::move(probe)),
        scheme_(std::move(scheme)),
        estimator_(twin.upper_bounds() - twin.lower_bounds(), options_.measurement_variance,
                   options_.trajectory),
        audit_(options_.audit_period, options_.audit_window),
        covariance_eigen_(twin.control_dimension()) {
    const Index d = twin.control_dimension();
    if constexpr (N != Dynamic) require_dimension("twin.control_dimension()", d, N);
    RandomStream initial = stream.substream("initial_offset");
    mean_.resize(d);
    initial.fill_normal(mean_);
    mean_ *= std::sqrt(options_.initial_variance);
    covariance_ = CovarianceMatrix::Identity(d, d) * options_.initial_variance;
    covariance_eigen_.compute(covariance_);  // sets the solver's `info`: copies may read it
    estimator_.reset(0, mean_);
    if constexpr (requires { probe_.reseed(stream); }) probe_.reseed(stream.substream("probe"));
    process_variance_ = options_.process_variance;
    const VectorX width = twin.upper_bounds() - twin.lower_bounds();
    max_probe_ = options_.max_probe_fraction * width;
    max_offset_ = options_.max_offset_fraction * width;
    max_correction_step_ = options_.correction_step_fraction * width;
    max_surprise_step_ = options_.surprise_step_fraction * width;
    applied_correction_.setZero(d);
    correction_.resize(d);
    check_margin_ = surrogate_.steps();
    covariance_ceiling_ = std::pow(options_.covariance_ceiling_fraction * width.minCoeff(), 2);
    probe_vector_.resize(d);
    control_.setZero(d);  // defined before the first proposal: snapshots save it
    model_.center.setZero(d);
    model_.half_gradient.setZero(d);
    model_.hessian.setZero(d, d);
    model_center_.resize(d);
    check_points_.resize(d, 2);
    recent_innovations_.assign(static_cast<std::size_t>(options_.trajectory.change_window) + 3,
                               0.0);
    recent_surprises_.assign(recent_innovations_.size(), false);
    plant_regrets_.assign(static_cast<std::size_t>(options_.regret_window), 0.0);
    regret_order_ = plant_regrets_;
    if constexpr (TwinWithKeptAssemblies<T>) {
      const auto kept = static_cast<std::size_t>(options_.trajectory.max_history);
      kept_assemblies_.resize(kept);
      kept_times_.assign(kept, -1);
      kept_model_errors_.assign(kept, std::numeric_limits<double>::infinity());
      candidates_.reserve(kept);
    }
    entry_point_.resize(d);
    entry_offset_.resize(d);
    const Index m = scheme_.num_points(d);
    mean_weights_.resize(m);
    covariance_weights_.resize(m);
    scheme_.weights(d, mean_weights_, covariance_weights_);
    points_.resize(d, m);
    sigma_preview_.measurements.resize(m);
    sigma_preview_.cross_covariance.resize(d);
    sigma_preview_.gain.resize(d);
    shifted_.resize(d, m);
    point_values_.resize(m);
    gain_.resize(d);
    probe_signal_.resize(d);
    probe_spread_.resize(d);
  }

  /// Chooses u_t for assembly x_t (steps 1–3 of the file comment).
  [[nodiscard]] ControlVector propose(const Assembly& assembly) {
    const IndividualControl u0 = optimum_(assembly);
    report_.reset();
    // Where the last assembly's model erred, so will this one's: its probe is priced by the
    // plant's regret and designed before the model, which is then fitted where it puts the plant.
    const bool last_model_erred = step_.model_variance > 0.0;
    const bool price_by_regret = options_.regret_probe > 0.0 && last_model_erred;
    step_ = ActiveStepReport{};
    report_.individual_control = u0.control;
    report_.optimal_quality = u0.quality;
    report_.optimizer_evaluations = u0.evaluations;

    step_.process_variance = process_variance_;
    center_ = u0.control;

    quadratic_ = false;
    audited_arm_.reset();
    bool probe_designed = false;
    std::uint64_t evaluations = 0;
    time_ = assemblies_;
    if (assemblies_ >= retry_at_) {
      // The model is fitted where the twin will be evaluated if the estimate is right: at the
      // twin-frame control u − δû without the probe, inside the box (for a twin whose Q² is a
      // quadratic, anywhere is the same).
      if (estimator_.fit_time() != time_) estimator_.fit(time_);
      const bool wanted = estimator_.significant() || restarted_;
      bool correct = wanted && !held_back();
      if (options_.fit_at_audited_arm && wanted) {
        // The audit picks its arm now, from the last assembly's model, and the model is fitted
        // where that arm puts the plant.
        audited_arm_ = audit_decision(last_model_erred, !correct);
        if (audited_arm_) correct = *audited_arm_;
      }
      model_center_ = center_.cwiseMax(twin_->lower_bounds()).cwiseMin(twin_->upper_bounds());
      if (correct) {
        bound_correction(estimator_.position());
        model_center_ += correction_;
      }
      model_center_ -= estimator_.position();
      // Within the twin's box, where it is defined (a lost estimate points outside it).
      model_center_ = model_center_.cwiseMax(twin_->lower_bounds()).cwiseMin(twin_->upper_bounds());
      if (price_by_regret) {
        design_probe();  // from the last assembly's model
        amplify_probe_where_models_err();
        price_probe_by_regret();
        probe_designed = true;
        model_center_ += probe_vector_;
        model_center_ =
            model_center_.cwiseMax(twin_->lower_bounds()).cwiseMin(twin_->upper_bounds());
      }
      // A twin that failed (TwinError) says nothing about its model: the model is tried again
      // at the next assembly, not after quadratic_retry assemblies on sigma points.
      Index retry = options_.quadratic_retry;
      try {
        evaluations += fit_model(assembly, estimator_.position_covariance());
      } catch (const TwinError& error) {
        report_.fallback = error.what();  // fit_model sets quadratic_ only once it succeeds
        retry = 1;
      } catch (const std::exception& error) {
        report_.fallback = error.what();
      }
      if (!quadratic_) retry_at_ = assemblies_ + retry;
    }
    step_.quadratic = quadratic_;
    ++assemblies_;
    if (quadratic_) {
      mean_ = estimator_.position();
      covariance_ = estimator_.position_covariance();
    } else {
      covariance_.diagonal().array() += process_variance_;  // the random walk, eq. (5c)
      bound_covariance();
    }
    step_.history = estimator_.history_size();
    report_.default_control = center_ + mean_;

    if (quadratic_) {
      // The probe, priced by the model (unless it was priced by regret before the fit).
      if (!probe_designed) design_probe();
    } else {
      // Without a model that holds, a probe cannot be priced: the controller is then the
      // default controller (eq. 9) with a sigma-point update. (Probing along P's axes with
      // H = I was measured to lose a RuggedTwin's offset.)
      probe_vector_.setZero();
    }
    step_.probe_norm = probe_vector_.norm();
    // While the estimator's history does not show an offset significantly, the control is not
    // corrected (the baseline's u0 plus the probe): a twin whose quality hardly depends on the
    // offset would otherwise be corrected by a fit of its model's errors.
    step_.corrected = !quadratic_ || estimator_.significant() || restarted_;
    // Do no harm: an estimate that keeps failing to predict the plant (a model that errs, or a
    // plant that is not the twin) is not applied (the control falls back to u0 + p) until it
    // predicts again; nor is one after surprises no refit explains, or beyond the correction's
    // reach (held_back()).
    step_.correction_wanted = step_.corrected;
    if (quadratic_) {
      step_.held_by_innovations = harmful();
      step_.held_by_surprises = unexplained();
      step_.held_beyond_reach = beyond_reach();
      if (held_back()) step_.corrected = false;
    }
    const bool held_by_rule = step_.correction_wanted && !step_.corrected;
    if (options_.fit_at_audited_arm) {
      step_.audited = quadratic_ && audited_arm_.has_value();
      if (step_.audited) step_.corrected = step_.corrected && *audited_arm_;
    } else {
      audit(step_.correction_wanted);
    }
    step_.held_by_audit = step_.correction_wanted && !held_by_rule && !step_.corrected;
    control_ =
        (center_ + probe_vector_).cwiseMax(twin_->lower_bounds()).cwiseMin(twin_->upper_bounds());
    if (step_.corrected) {
      bound_correction(mean_);
      control_ += correction_;
      applied_correction_ = correction_;
    }
    report_.control = control_;
    report_.quality_evaluations = evaluations;
    pending_ = true;
    return control_;
  }

  /// Updates the estimate with the measured quality z_t of the applied control (step 4). A
  /// control other than the proposal, or an observe without a propose, is updated with sigma
  /// points (its model may not hold there).
  /// A TwinError in the sigma-point mode's update drops z: the estimate stays as predicted, and
  /// last_proposal().dropped_measurement says why.
  /// @throws NonFiniteError (z), DimensionMismatchError (control), with the state unchanged;
  ///         the twin's other errors in the sigma-point mode, also with the state unchanged.
  void observe(const Assembly& assembly, const ControlVector& control, double z) {
    require_dimension("control", control.size(), dimension());
    require_finite("z", z);
    require_finite("control", control);
    if (pending_ && quadratic_ && control == control_) {
      if (step_.audited) record_audit(z);
      update_estimator(assembly, control, z);
    } else {
      try {
        update_sigma_points(assembly, control, z);
      } catch (const TwinError& error) {
        // As a filter drops a missing measurement: the estimate stays as predicted (the update
        // changes nothing before its last twin call succeeded).
        report_.dropped_measurement = error.what();
        step_.gated = false;
      }
    }
    pending_ = false;
  }

  /// Restarts the estimate at N(estimate, covariance) — a re-initialization from outside (a
  /// measurement of the fixture, a least-squares fit over a history) — keeping q and the model;
  /// the estimator forgets its history, and the estimate is applied from the next proposal on
  /// (it does not wait for the history to show the offset significantly, nor is it bounded by a
  /// surprise of the estimate it replaces; with ActiveOptions::correction_step_fraction the
  /// correction moves towards it from the one last applied, at that step per assembly).
  /// @throws DimensionMismatchError, NonFiniteError, NotPositiveDefiniteError, with the state
  ///         unchanged.
  void restart(const ControlVector& estimate, const CovarianceMatrix& covariance) {
    require_dimension("estimate", estimate.size(), dimension());
    require_finite("estimate", estimate);
    require_shape("covariance", covariance, dimension(), dimension());
    require_finite("covariance", covariance);
    require_symmetric("covariance", covariance);
    require_positive_definite("covariance", covariance);
    estimator_.reset(assemblies_, estimate, covariance);
    restarted_ = true;   // an estimate given from outside is applied without waiting for evidence
    surprised_ = false;  // nor bounded or held back by what surprised the estimate it replaces
    std::fill(recent_surprises_.begin(), recent_surprises_.end(), false);
    trial_surprise_ = 0;
    mean_ = estimate;
    covariance_ = covariance;
    pending_ = false;
  }

  [[nodiscard]] Index dimension() const noexcept { return mean_.size(); }
  [[nodiscard]] const ControlVector& offset_estimate() const noexcept { return mean_; }
  [[nodiscard]] MatrixX offset_covariance() const { return covariance_; }
  [[nodiscard]] const CovarianceMatrix& covariance() const noexcept { return covariance_; }
  [[nodiscard]] double process_variance() const noexcept { return process_variance_; }
  [[nodiscard]] const ActiveOptions& options() const noexcept { return options_; }
  [[nodiscard]] const ProposalReport& last_proposal() const noexcept { return report_; }
  [[nodiscard]] const ActiveStepReport& last_step() const noexcept { return step_; }
  /// The model of the last proposal (valid when last_step().quadratic).
  [[nodiscard]] const QuadraticModel<N>& model() const noexcept { return model_; }

  static constexpr std::string_view json_format = "twincal.active_controller";

  /// Everything that carries over from one assembly to the next: the estimate δû, P and q; the
  /// estimator (its history, snapshots, prior and misfit medians), the surrogate's kept H and
  /// its age, the probe's stream; the counters (assemblies, the pending proposal's time, the
  /// retry of the quadratic model); the pending proposal (u_t, whether its model held, the
  /// model, which observe updates with), the correction last applied and whether the last
  /// assembly surprised (ActiveOptions::surprise_step_fraction); the do-no-harm rings
  /// (normalized innovations and which of them were unexplained surprises, the audit's regrets
  /// and counts); the plant's last regrets, which price the probe; the assemblies kept for
  /// relinearization, with their checks (ε, for the τ² of their refits); and the last proposal's
  /// reports. Not the workspaces (sigma points, check points, the eigensolver of the covariance
  /// bound, the relinearization candidates), which are rewritten before they are read, nor the
  /// settings derived from the twin's box.
  [[nodiscard]] nlohmann::json save() const requires SnapshotProbe<Probe> {
    using json_state::doubles_to_json;
    using json_state::number_to_json;
    nlohmann::json saved{{"format", json_format},
                         {"dimension", dimension()},
                         {"mean", doubles_to_json(mean_)},
                         {"covariance", json_state::matrix_to_json(covariance_)},
                         {"process_variance", number_to_json(process_variance_)},
                         {"assemblies", assemblies_},
                         {"time", time_},
                         {"retry_at", retry_at_},
                         {"restarted", restarted_},
                         {"surprised", surprised_},
                         {"quadratic", quadratic_},
                         {"pending", pending_},
                         {"control", doubles_to_json(control_)},
                         {"applied_correction", doubles_to_json(applied_correction_)},
                         {"model", json_state::model_to_json(model_)},
                         {"recent_innovations", doubles_to_json(recent_innovations_)},
                         {"recent_surprises", recent_surprises_},
                         {"innovation_count", innovation_count_},
                         {"trial_surprise", trial_surprise_},
                         {"trial_failed", trial_failed_},
                         {"plant_regrets", doubles_to_json(plant_regrets_)},
                         {"regret_count", regret_count_},
                         {"report", json_state::report_to_json(report_)},
                         {"step", active_step_report_to_json(step_)},
                         {"surrogate", surrogate_.save()},
                         {"probe", probe_.save()},
                         {"estimator", estimator_.save()}};
    audit_.save(saved);
    nlohmann::json kept = nlohmann::json::array();
    if constexpr (TwinWithKeptAssemblies<T>) {
      for (std::size_t slot = 0; slot < kept_times_.size(); ++slot) {
        if (kept_times_[slot] < 0) continue;
        kept.push_back({{"slot", slot},
                        {"time", kept_times_[slot]},
                        {"assembly", json_state::assembly_to_json(kept_assemblies_[slot])},
                        {"model_error", json_state::number_to_json(kept_model_errors_[slot])}});
      }
    }
    saved["kept_assemblies"] = std::move(kept);
    return saved;
  }

  /// Restores a snapshot of save() into a controller built like the saved one (same twin,
  /// options, probe and scheme; kept assemblies must be assemblies of the twin).
  /// @throws InvalidArgumentError, DimensionMismatchError, NonFiniteError naming the field
  ///         ("estimator.history[4].quality"); the controller unchanged.
  void restore(const nlohmann::json& saved) requires SnapshotProbe<Probe> {
    using json_state::field;
    using json_state::read_bool;
    using json_state::read_integer_field;
    const Index d = dimension();
    json_state::require_header(saved, json_format, d);
    ControlVector mean(d);
    json_state::read_doubles(field(saved, "mean"), "mean", mean);
    CovarianceMatrix covariance(d, d);
    json_state::read_matrix(field(saved, "covariance"), "covariance", covariance);
    const double process_variance = json_state::read_double_field(saved, "process_variance");
    const Index assemblies = read_integer_field(saved, "assemblies", 0);
    const Index time = read_integer_field(saved, "time", 0);
    const Index retry_at = read_integer_field(saved, "retry_at", 0);
    const bool restarted = read_bool(saved, "restarted");
    const bool surprised = read_bool(saved, "surprised");
    const bool quadratic = read_bool(saved, "quadratic");
    const bool pending = read_bool(saved, "pending");
    ControlVector control(d);
    json_state::read_doubles(field(saved, "control"), "control", control);
    ControlVector applied_correction(d);
    json_state::read_doubles(field(saved, "applied_correction"), "applied_correction",
                             applied_correction);
    const nlohmann::json& saved_model = field(saved, "model");
    QuadraticModel<N> model =
        json_state::within("model", [&] { return json_state::read_model<N>(saved_model, d); });
    std::vector<double> recent_innovations = recent_innovations_;
    json_state::read_doubles(field(saved, "recent_innovations"), "recent_innovations",
                             recent_innovations);
    std::vector<bool> recent_surprises = recent_surprises_;
    json_state::read_bools(field(saved, "recent_surprises"), "recent_surprises", recent_surprises);
    const auto innovation_count =
        static_cast<std::size_t>(json_state::read_count(saved, "innovation_count"));
    // A surprise of the trial is one of the innovations counted so far (or none, 0).
    const auto trial_surprise = static_cast<std::size_t>(
        read_integer_field(saved, "trial_surprise", 0, static_cast<Index>(innovation_count)));
    const bool trial_failed = read_bool(saved, "trial_failed");
    std::vector<double> plant_regrets = plant_regrets_;
    json_state::read_doubles(field(saved, "plant_regrets"), "plant_regrets", plant_regrets);
    const auto regret_count =
        static_cast<std::size_t>(json_state::read_count(saved, "regret_count"));
    DoNoHarmAudit audit = audit_;
    audit.restore(saved);
    const nlohmann::json& saved_report = field(saved, "report");
    ProposalReport report =
        json_state::within("report", [&] { return json_state::read_report(saved_report, d); });
    const nlohmann::json& saved_step = field(saved, "step");
    const ActiveStepReport step =
        json_state::within("step", [&] { return read_active_step_report(saved_step); });
    std::vector<Assembly> kept_assemblies;
    std::vector<Index> kept_times;
    std::vector<double> kept_model_errors;
    const nlohmann::json& saved_kept =
        json_state::require_array(field(saved, "kept_assemblies"), "kept_assemblies");
    if constexpr (TwinWithKeptAssemblies<T>) {
      kept_assemblies = kept_assemblies_;
      kept_times.assign(kept_times_.size(), -1);
      kept_model_errors.assign(kept_times_.size(), std::numeric_limits<double>::infinity());
      for (std::size_t i = 0; i < saved_kept.size(); ++i) {
        json_state::within(fmt::format("kept_assemblies[{}]", i), [&] {
          const nlohmann::json& entry = saved_kept[i];
          const auto slot = static_cast<std::size_t>(
              read_integer_field(entry, "slot", 0, std::ssize(kept_times) - 1));
          kept_times[slot] = read_integer_field(entry, "time", 0);
          json_state::read_assembly(field(entry, "assembly"), "assembly", kept_assemblies[slot]);
          kept_model_errors[slot] =
              json_state::read_double_field(entry, "model_error", json_state::Values::any);
          require_non_negative("model_error", kept_model_errors[slot]);
        });
      }
    } else {
      require_dimension("kept_assemblies", std::ssize(saved_kept), 0);
    }
    const nlohmann::json& saved_surrogate = field(saved, "surrogate");
    const nlohmann::json& saved_probe = field(saved, "probe");
    const nlohmann::json& saved_estimator = field(saved, "estimator");
    QuadraticSurrogate<T, N> surrogate = surrogate_;
    json_state::within("surrogate", [&] { surrogate.restore(saved_surrogate); });
    // The probe and then the estimator, each all or nothing; the probe goes back to where it
    // was if the estimator's part is refused.
    const nlohmann::json probe_before = probe_.save();
    json_state::within("probe", [&] { probe_.restore(saved_probe); });
    try {
      json_state::within("estimator", [&] { estimator_.restore(saved_estimator); });
    } catch (...) {
      probe_.restore(probe_before);
      throw;
    }

    // Nothing throws from here on.
    surrogate_ = std::move(surrogate);
    mean_ = mean;
    covariance_ = covariance;
    process_variance_ = process_variance;
    assemblies_ = assemblies;
    time_ = time;
    retry_at_ = retry_at;
    restarted_ = restarted;
    surprised_ = surprised;
    quadratic_ = quadratic;
    pending_ = pending;
    control_ = control;
    applied_correction_ = applied_correction;
    model_ = std::move(model);
    recent_innovations_.swap(recent_innovations);
    recent_surprises_.swap(recent_surprises);
    innovation_count_ = innovation_count;
    trial_surprise_ = trial_surprise;
    trial_failed_ = trial_failed;
    plant_regrets_.swap(plant_regrets);
    regret_count_ = regret_count;
    audit_ = std::move(audit);
    if constexpr (TwinWithKeptAssemblies<T>) {
      kept_assemblies_.swap(kept_assemblies);
      kept_times_.swap(kept_times);
      kept_model_errors_.swap(kept_model_errors);
    }
    report_ = std::move(report);
    step_ = step;
  }

 private:
  // The correction to apply for the estimate δû, into correction_: clamp(δû, ±max_offset_), then
  // moved at most max_correction_step_ (correction_step_fraction > 0) and, after a surprise,
  // max_surprise_step_ (surprise_step_fraction > 0) per locator from the last applied one.
  void bound_correction(const ControlVector& estimate) {
    correction_ = estimate.cwiseMax(-max_offset_).cwiseMin(max_offset_);
    if (options_.correction_step_fraction > 0.0) bound_step(max_correction_step_);
    if (surprised_ && options_.surprise_step_fraction > 0.0) bound_step(max_surprise_step_);
  }

  // correction_ moved at most `step` per locator from the last applied correction.
  void bound_step(const ControlVector& step) {
    correction_ =
        applied_correction_ + (correction_ - applied_correction_).cwiseMax(-step).cwiseMin(step);
  }

  // The probe of the Probe policy, priced by model_. T = tr(HP)/tr(HQ) (for designs that price
  // information, as InformationProbe): the assemblies a random walk of variance q takes to add
  // back the uncertainty there is now.
  void design_probe() {
    const double refill = process_variance_ * model_.hessian.trace();
    const double uncertainty = model_.hessian.cwiseProduct(covariance_).sum();  // tr(HP)
    step_.horizon = refill > 0.0 ? std::clamp(uncertainty / refill, 1.0, options_.max_horizon)
                                 : options_.max_horizon;
    const ProbeContext<N> context{.hessian = model_.hessian,
                                  .half_gradient = model_.half_gradient,
                                  .covariance = covariance_,
                                  .value = model_.value,
                                  .measurement_variance = options_.measurement_variance,
                                  .horizon = step_.horizon,
                                  .max_probe = max_probe_};
    probe_.design(context, probe_vector_);
  }

  // Where the last model erred: the probe × erring_probe_gain (clipped to the largest probe) when
  // the quality signal it then carries about the offset, √(pᵀHPHp) / z*, reaches σz. Below that
  // (the door: its quality hardly depends on the offset) a larger probe teaches nothing and costs
  // all the same.
  void amplify_probe_where_models_err() {
    const double gain = options_.erring_probe_gain;
    if (gain == 1.0) return;
    probe_signal_.noalias() = model_.hessian * probe_vector_;
    probe_spread_.noalias() = covariance_ * probe_signal_;
    const double signal = gain * std::sqrt(std::max(0.0, probe_signal_.dot(probe_spread_)));
    if (!(signal >= std::sqrt(options_.measurement_variance) * report_.optimal_quality)) return;
    scale_probe(gain);
  }

  // The probe × factor, clipped to the largest probe.
  void scale_probe(double factor) {
    probe_vector_ *= factor;
    probe_vector_ = probe_vector_.cwiseMax(-max_probe_).cwiseMin(max_probe_);
  }

  // Scales the probe up, where its model cost pᵀHp is smaller, to regret_probe × the regret the
  // plant shows: the median of its last regret_window regrets z² − z*², less twice the noise σz
  // puts in z² (2 z* σz), then clipped to the largest probe. Nothing before the window is full,
  // for a zero probe, or where the regret is within the noise (the door: its quality hardly
  // depends on the offset, and a probe priced by noise cost 16 times the baseline's residual).
  void price_probe_by_regret() {
    if (regret_count_ < plant_regrets_.size()) return;
    const double noise = 2.0 * report_.optimal_quality * std::sqrt(options_.measurement_variance);
    const double regret =
        median_of_first(plant_regrets_, plant_regrets_.size(), regret_order_) - 2.0 * noise;
    probe_signal_.noalias() = model_.hessian * probe_vector_;
    const double cost = probe_vector_.dot(probe_signal_);
    if (!(regret > 0.0) || !(cost > 0.0)) return;
    step_.plant_regret = regret;
    const double wanted = options_.regret_probe * regret;
    if (cost >= wanted) return;
    scale_probe(std::sqrt(wanted / cost));
  }

  // Fits the quadratic model at model_center_ and checks it at model_center_ ± (2·sqrt(diag P)
  // + h) in a sign pattern, P the offset's covariance and h the surrogate's step (where the
  // model will be used: within the estimate's uncertainty of the point it expects); a failed
  // check with a kept H refits H once. Sets quadratic_.
  std::uint64_t fit_model(const Assembly& assembly, const CovarianceMatrix& covariance) {
    std::uint64_t evaluations = 0;
    for (int attempt = 0; attempt < 2; ++attempt) {
      const bool refit = surrogate_.hessian_stale();
      step_.hessian_refitted = step_.hessian_refitted || refit;
      evaluations += surrogate_.fit(assembly, model_center_, model_);
      const Index d = dimension();
      for (Index i = 0; i < d; ++i) {
        const double reach = 2.0 * std::sqrt(covariance(i, i)) + check_margin_(i);
        check_points_(i, 0) = model_center_(i) + ((i % 2 == 0) ? reach : -reach);
        check_points_(i, 1) = model_center_(i) - ((i / 2) % 2 == 0 ? reach : -reach);
      }
      evaluations += surrogate_.check(assembly, model_, check_points_, step_.model_error);
      quadratic_ = step_.model_error <= options_.surrogate.tolerance;
      if (quadratic_ || refit) break;
      surrogate_.invalidate_hessian();
    }
    step_.model_variance = 0.0;
    if (!quadratic_ && options_.weigh_model_error) {
      weigh_model_error(covariance);
      quadratic_ = true;
    }
    return evaluations;
  }

  // τ², the variance of the model's error in Q where the plant is expected: about one standard
  // deviation of P from the model's centre (ρ·R in units of the check's reach R = 2√P_ii + h,
  // ρ² = mean P_ii/R_i²), not at R. At the check the model errs by ε·c in Q², so by
  // ε·c/(2√c) = ε√c/2 in Q; the error is taken to grow with the fourth power of the distance
  // (a quadratic's error against a quartic such as stiffening), ε(ρR) = ε(R) ρ⁴. Measured on
  // contact, stiffening and kink twins at d = 3 and 12 (docs/reproduction.md, "Black-box
  // twins"): a τ that grows more slowly (ρ², ρ, or the growth measured by a second check at
  // R/2) weighs good assemblies as if their model failed and loses the offset more often; τ = 0
  // does about as well as ρ⁴ except on contact.
  void weigh_model_error(const CovarianceMatrix& covariance) {
    step_.model_variance =
        model_error_variance(step_.model_error, model_.value,
                             reach_fraction(covariance, [&](Index i) { return covariance(i, i); }));
  }

  // ρ², the mean over the locators of squared_distance(i) / R_i², R = 2√P_ii + h the check's
  // reach under `covariance`.
  template <typename SquaredDistance>
  [[nodiscard]] double reach_fraction(const CovarianceMatrix& covariance,
                                      SquaredDistance squared_distance) const {
    const Index d = dimension();
    double sum = 0.0;
    for (Index i = 0; i < d; ++i) {
      const double reach = 2.0 * std::sqrt(covariance(i, i)) + check_margin_(i);
      sum += squared_distance(i) / (reach * reach);
    }
    return sum / static_cast<double>(d);
  }

  // The ρ⁴ law of weigh_model_error: τ² of a model of value c that erred by `relative_error` at
  // the check's reach R, used at ρ·R from its centre (ρ² = `reach_fraction`).
  [[nodiscard]] static double model_error_variance(double relative_error, double value,
                                                   double reach_fraction) {
    const double error =
        0.5 * relative_error * std::sqrt(std::max(value, 0.0)) * reach_fraction * reach_fraction;
    return error * error;
  }

  // τ² of an entry refitted where the fit puts it: the fit uses it within relinearization_reach
  // · h of its new centre until it is refitted again, so its error is the ρ⁴ law's at that
  // distance (ρ_i = reach · h_i / R_i, R from the covariance now), not at one standard deviation
  // of P; never more than it had. `relative_error` is the entry's own check (a non-finite one
  // keeps the τ² it had).
  [[nodiscard]] double refitted_model_variance(double relative_error, double value,
                                               double before) const {
    if (!std::isfinite(relative_error)) return before;
    const double fraction = reach_fraction(estimator_.position_covariance(), [&](Index i) {
      const double used = options_.relinearization_reach * check_margin_(i);
      return used * used;
    });
    return std::min(before, model_error_variance(relative_error, value, fraction));
  }

  // The estimator's update: z joins the history, and the estimate moves to the next assembly.
  void update_estimator(const Assembly& assembly, const ControlVector& control, double z) {
    const double best = report_.optimal_quality;
    plant_regrets_[regret_count_ % plant_regrets_.size()] = z * z - best * best;
    ++regret_count_;
    step_.normalized_innovation = estimator_.add(time_, model_, control, z, step_.model_variance);
    recent_innovations_[innovation_count_ % recent_innovations_.size()] =
        step_.normalized_innovation;

    ++innovation_count_;
    const Index changes_before = estimator_.changes();
    using ChangeTest = typename ConstantVelocityEstimator<N>::ChangeTest;
    const ChangeTest test = TwinWithKeptAssemblies<T> && options_.change_test_after_refit
                                ? ChangeTest::after_refit
                                : ChangeTest::now;
    estimator_.fit(time_ + 1, test);
    // The report covers every fit of this assembly (a relinearization fits again): a change
    // declared by either, and the gate's larger reading (fmax ignores a gate not consulted).
    step_.change_ratio = estimator_.change_ratio();
    if constexpr (TwinWithKeptAssemblies<T>) {
      const std::size_t at = static_cast<std::size_t>(time_) % kept_assemblies_.size();
      kept_assemblies_[at] = assembly;
      kept_times_[at] = time_;
      kept_model_errors_[at] = step_.model_error;
      if (relinearize()) {
        estimator_.fit(time_ + 1, test);
        step_.change_ratio = std::fmax(step_.change_ratio, estimator_.change_ratio());
      }
      if (test == ChangeTest::after_refit) {
        estimator_.test_change();
        step_.change_ratio = std::fmax(step_.change_ratio, estimator_.change_ratio());
      }
    }
    step_.velocity_change = estimator_.changes() > changes_before;
    step_.normalized_residual = estimator_.normalized_residual(estimator_.history_size() - 1);
    // During the trial (ActiveOptions::trial_innovations) a refit that explains z proves nothing.
    const bool on_trial = innovation_count_ <= static_cast<std::size_t>(options_.trial_innovations);
    surprised_ =
        step_.normalized_innovation > options_.innovation_gate * options_.innovation_gate &&
        (on_trial || step_.normalized_residual > 1.0);
    if (surprised_ && on_trial) {
      trial_surprise_ = innovation_count_;
      trial_failed_ = true;
    }
    recent_surprises_[(innovation_count_ - 1) % recent_surprises_.size()] = surprised_;
    step_.misfit_scale = estimator_.misfit_scale();
    step_.prediction_scale = estimator_.prediction_scale();
    step_.fit_unit = estimator_.fit_unit();
    step_.history = estimator_.history_size();
    mean_ = estimator_.position();
    covariance_ = estimator_.position_covariance();
  }

  // Refits the models of the history's entries that the fit now uses farthest beyond their
  // finite-difference stencil (|r_i| > relinearization_reach · h_i on some locator, r the entry's
  // point under the fit minus its model's centre), within relinearization_budget · (d + 1)²
  // evaluations: Gauss–Newton on the twin itself, with the quadratic model only between refits.
  // Only entries whose model failed its check (τ² > 0) are refitted: elsewhere the model is the
  // twin. Returns whether any entry changed.
  bool relinearize() {
    const Index d = dimension();
    // The budget is in twin evaluations, relinearization_budget · (d + 1)²: about d + 1 refits
    // of 2d + 1 evaluations (central differences from Q², Gauss–Newton from the deviations).
    const Index budget = static_cast<Index>(options_.relinearization_budget *
                                            static_cast<double>((d + 1) * (d + 1))) /
                         surrogate_.refit_evaluations();
    if (budget <= 0) return false;
    candidates_.clear();
    for (Index i = 0; i < estimator_.history_size(); ++i) {
      if (estimator_.entry_model_variance(i) <= 0.0) continue;
      const Index time = estimator_.entry_time(i);
      const std::size_t at = static_cast<std::size_t>(time) % kept_assemblies_.size();
      if (kept_times_[at] != time) continue;
      estimator_.entry_point(i, entry_point_, entry_offset_);
      const double reach = entry_offset_.cwiseAbs().cwiseQuotient(check_margin_).maxCoeff();
      if (reach > options_.relinearization_reach) candidates_.emplace_back(reach, i);
    }
    const auto count = std::min(static_cast<std::ptrdiff_t>(budget), std::ssize(candidates_));
    std::partial_sort(candidates_.begin(), candidates_.begin() + count, candidates_.end(),
                      [](const auto& a, const auto& b) { return a.first > b.first; });
    bool changed = false;
    for (std::ptrdiff_t k = 0; k < count; ++k) {
      const Index i = candidates_[static_cast<std::size_t>(k)].second;
      const Index time = estimator_.entry_time(i);
      const std::size_t at = static_cast<std::size_t>(time) % kept_assemblies_.size();
      estimator_.entry_point(i, entry_point_, entry_offset_);
      entry_point_ = entry_point_.cwiseMax(twin_->lower_bounds()).cwiseMin(twin_->upper_bounds());
      try {
        report_.quality_evaluations += surrogate_.refit_gradient(
            kept_assemblies_[at], entry_point_, estimator_.entry_hessian(i), entry_model_);
      } catch (const std::exception&) {
        break;  // the entry keeps its model; the twin's trouble shows at the next proposal
      }
      estimator_.relinearize(i, entry_model_,
                             refitted_model_variance(kept_model_errors_[at], entry_model_.value,
                                                     estimator_.entry_model_variance(i)));
      changed = true;
    }
    return changed;
  }

  // Do no harm, measured (DoNoHarmAudit): where the estimate is in doubt — the twin's model
  // failed its check (τ² > 0), or the estimator's innovations misfit the plant by audit_misfit or
  // more (its prediction_scale(): a plant that is not the twin), or the twin failed its trial
  // (audit_after_failed_trial) — every assembly whose estimate would be applied is audited (one
  // held_back() joins the uncorrected arm). After the model's fit, from its own check; with
  // fit_at_audited_arm before it (audit_decision), from the last assembly's.
  void audit(bool wanted) {
    step_.audited = false;
    if (!quadratic_ || !wanted) return;
    const std::optional<bool> arm = audit_decision(step_.model_variance > 0.0, !step_.corrected);
    step_.audited = arm.has_value();
    if (arm) step_.corrected = *arm;
  }

  // The audit's arm for an assembly whose estimate would be applied: in doubt where a model
  // erred, the estimator misfits the plant by audit_misfit or more, or the twin failed its trial
  // (DoNoHarmAudit::decide).
  [[nodiscard]] std::optional<bool> audit_decision(bool erring_model, bool held_back) {
    const bool doubt = erring_model || estimator_.prediction_scale() >= options_.audit_misfit ||
                       (options_.audit_after_failed_trial && trial_failed_);
    return audit_.decide(doubt, erring_model, held_back);
  }

  // The audited assembly's relative regret (z − z*)/z* joins its arm; assemblies_ counts
  // proposals, so this one's time is assemblies_.
  void record_audit(double z) {
    const double best = std::max(report_.optimal_quality, std::numeric_limits<double>::min());
    audit_.record(assemblies_, step_.corrected, (z - best) / best);
  }

  // The estimate is not applied where a do-no-harm rule holds it back: the plant keeps
  // surprising it (harmful()), with surprises no refit explains (unexplained()), or it lies
  // beyond the correction's reach (beyond_reach()).
  [[nodiscard]] bool held_back() const noexcept {
    return harmful() || unexplained() || beyond_reach();
  }

  // Do no harm: innovations beyond the gate (innovation_gate σ) in more of the last
  // change_window + 3 assemblies than a change of velocity explains (its change_window assemblies
  // before the estimator restarts, and one more) mean the estimate does not predict the plant, so
  // applying it could cost more than it buys. (Measured on contact twins, d = 3 and 12: a majority
  // of the five halves what contact at d = 3 gains; all five lets d = 12 run 1.4× the baseline.)
  [[nodiscard]] bool harmful() const noexcept {
    const double gate2 = options_.innovation_gate * options_.innovation_gate;
    const std::size_t kept = std::min(recent_innovations_.size(), innovation_count_);
    std::size_t beyond = 0;
    for (std::size_t i = 0; i < kept; ++i) beyond += recent_innovations_[i] > gate2 ? 1U : 0U;
    return beyond >= static_cast<std::size_t>(options_.trajectory.change_window) + 2;
  }

  // At least hold_after_surprises of the last change_window + 3 assemblies surprised the estimate
  // and stayed unexplained by its refit (ActiveOptions::hold_after_surprises): the twin does not
  // explain the plant there, whatever the estimate.
  [[nodiscard]] bool unexplained() const noexcept {
    // A surprise of the trial holds alone while it is in the ring (trial_innovations).
    if (trial_surprise_ > 0 && innovation_count_ - trial_surprise_ < recent_surprises_.size())
      return true;
    if (options_.hold_after_surprises <= 0) return false;
    const auto count = std::count(recent_surprises_.begin(), recent_surprises_.end(), true);
    return count >= options_.hold_after_surprises;
  }

  // An estimate beyond the correction's reach (|δû_i| > max_offset_ on some locator) is far
  // beyond any offset the box was built for: the estimator has lost the plant, and clamping
  // such an estimate puts the fixture at the reach's corner, where a plant that is not the twin
  // can answer with many times z* (ActiveOptions::clamp_beyond_reach).
  [[nodiscard]] bool beyond_reach() const noexcept {
    return !options_.clamp_beyond_reach &&
           (estimator_.position().array().abs() > max_offset_.array()).any();
  }

  // The unscented update of z (filters' measurement_statistics, as SigmaPointFilter's).
  void update_sigma_points(const Assembly& assembly, const ControlVector& control, double z) {
    const CholeskyResult<N> factor = cholesky(covariance_, {}, "offset covariance");
    sigma_point_statistics(assembly, control, factor.factor.lower(), 1.0);
    double innovation = z - sigma_preview_.predicted_measurement;
    double variance = sigma_preview_.innovation_variance;
    const double nis = innovation * innovation / variance;
    const double gate2 = options_.innovation_gate * options_.innovation_gate;
    step_.gated = nis > gate2;
    if (step_.gated) {
      // Overconfident: the update runs from P widened by how far ν is beyond the gate (the
      // widened points cost one more batch; P changes only once it succeeded).
      const double widening = nis / gate2;
      sigma_point_statistics(assembly, control, factor.factor.lower(), std::sqrt(widening));
      covariance_ *= widening;
      innovation = z - sigma_preview_.predicted_measurement;
      variance = sigma_preview_.innovation_variance;
    }
    gain_ = sigma_preview_.gain;
    commit(innovation, variance, nis);
    surprised_ = false;  // a random-walk update is no fit that could explain z
  }

  // The sigma points of N(δû, (scale L)(scale L)ᵀ) through the twin at `control`.
  template <typename Lower>
  void sigma_point_statistics(const Assembly& assembly, const ControlVector& control,
                              const Lower& lower, double scale) {
    scheme_.generate(mean_, lower, points_);
    if (scale != 1.0) points_ = ((points_.colwise() - mean_) * scale).colwise() + mean_;
    shifted_ = (-points_).colwise() + control;  // u − χ_i
    twin_->quality_batch(assembly, shifted_, point_values_);
    report_.quality_evaluations += static_cast<std::uint64_t>(points_.cols());
    measurement_statistics(points_, mean_, mean_weights_, covariance_weights_, point_values_,
                           options_.measurement_variance, sigma_preview_);
  }

  // x⁺ = x + K ν, P⁺ = P − K S Kᵀ, then the guards.
  void commit(double innovation, double variance, double nis) {
    mean_.noalias() += gain_ * innovation;
    covariance_.noalias() -= (gain_ * variance) * gain_.transpose();
    symmetrize(covariance_);
    bound_covariance();
    step_.normalized_innovation = nis;
    // Adapt q: innovations larger than predicted (ν²/S > 1) mean the offset moved more than the
    // random walk allowed.
    const double excess = std::clamp(nis - 1.0, -1.0, 3.0);
    process_variance_ = std::clamp(process_variance_ * std::exp(options_.adaptation_rate * excess),
                                   options_.min_process_variance, options_.max_process_variance);
  }

  // Floor and ceiling on P's eigenvalues (P stays symmetric positive definite and never claims
  // more uncertainty than the box allows).
  void bound_covariance() {
    covariance_eigen_.compute(covariance_);
    const Vector<N>& lambda = covariance_eigen_.eigenvalues();
    if (lambda.minCoeff() >= options_.covariance_floor &&
        lambda.maxCoeff() <= covariance_ceiling_) {
      return;
    }
    const SquareMatrix<N>& V = covariance_eigen_.eigenvectors();
    covariance_.noalias() =
        V * lambda.cwiseMax(options_.covariance_floor).cwiseMin(covariance_ceiling_).asDiagonal() *
        V.transpose();
  }

  const T* twin_;
  ActiveOptions options_;
  IndividualOptimum<T, O> optimum_;
  QuadraticSurrogate<T, N> surrogate_;
  Probe probe_;
  Scheme scheme_;
  ConstantVelocityEstimator<N> estimator_;
  DoNoHarmAudit audit_;
  ControlVector mean_;
  CovarianceMatrix covariance_;
  double process_variance_ = 0.0;
  ControlVector max_offset_;
  ControlVector max_correction_step_;
  ControlVector max_surprise_step_;
  ControlVector applied_correction_;  // the correction of the last corrected proposal
  ControlVector correction_;          // bound_correction()'s
  ControlVector check_margin_;
  ControlVector max_probe_;  // the ProbeContext's type: no converted temporary per assembly
  double covariance_ceiling_ = 0.0;
  // Per-assembly state and workspaces, sized once.
  ControlVector center_;        // u0
  ControlVector model_center_;  // where the model is fitted: the expected twin-frame control
  ControlVector probe_vector_;
  ControlVector probe_signal_;  // H p and P H p: the probe's workspace (gain, regret pricing)
  ControlVector probe_spread_;
  ControlVector control_;
  MatrixX check_points_;
  QuadraticModel<N> model_;
  Eigen::SelfAdjointEigenSolver<CovarianceMatrix> covariance_eigen_;
  VectorX mean_weights_;
  VectorX covariance_weights_;
  Matrix<N, Dynamic> points_;
  MatrixX shifted_;
  VectorX point_values_;
  MeasurementPreview<N, Dynamic> sigma_preview_;
  ControlVector gain_;
  std::vector<Assembly> kept_assemblies_;  // the estimator's assemblies, by time % max_history
  std::vector<Index> kept_times_;
  // Each kept assembly's check (its model's relative error ε), for the τ² of its refits.
  std::vector<double> kept_model_errors_;
  std::vector<std::pair<double, Index>> candidates_;  // relinearize(): (reach, entry)
  ControlVector entry_point_;
  ControlVector entry_offset_;
  QuadraticModel<N> entry_model_;
  // The plant's regrets z² − z*² of the last regret_window assemblies the estimator updated
  // with (a ring), their count, and a workspace for their median.
  std::vector<double> plant_regrets_;
  std::size_t regret_count_ = 0;
  std::vector<double> regret_order_;
  std::vector<double> recent_innovations_;  // ν²/S of the last change_window + 3 (a ring)
  std::vector<bool> recent_surprises_;      // whether each of them surprised_ (the same ring)
  std::size_t innovation_count_ = 0;
  // innovation_count_ just after the trial's last surprise (0: none; trial_innovations).
  std::size_t trial_surprise_ = 0;
  // A surprise of the trial was seen (ActiveOptions::audit_after_failed_trial); restart() keeps it.
  bool trial_failed_ = false;
  bool quadratic_ = false;
  bool pending_ = false;
  Index assemblies_ = 0;
  Index time_ = 0;  // the assembly of the pending proposal
  bool restarted_ = false;
  // The last assembly surprised (ActiveOptions::surprise_step_fraction): its z beyond the gate
  // before the fit and not explained by it. Set by the estimator's update, cleared by the
  // sigma-point update and by restart().
  bool surprised_ = false;
  std::optional<bool> audited_arm_;  // fit_at_audited_arm: the arm picked before the fit
  Index retry_at_ = 0;
  ProposalReport report_;
  ActiveStepReport step_;
};

}  // namespace twincal
