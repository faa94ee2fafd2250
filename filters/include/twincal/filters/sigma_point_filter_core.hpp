#pragma once
/// @file
/// `SigmaPointFilterCore<StateModel, MeasurementModel, Scheme, Form>`: the half of the
/// sigma-point Kalman filter of the paper's Sec. 2.3.1 that does not depend on how the covariance
/// is kept, shared by SigmaPointFilter (P itself) and SquareRootSigmaPointFilter (its Cholesky
/// factor L), which each hold one as a member. The core owns the models (5b)–(5c), the scheme and
/// its weights W(s_t) of eq. (11), the mean, the sigma points, the counters and the buffers of
/// the steps; the covariance form (a member policy satisfying CovarianceForm) owns P or L and
/// computes what depends on it: P⁻ in predict, P⁺ and its factor in a preview, the JSON field.
///
/// predict: χ_i* = f(χ_i), x⁻ = Σ Wm_i χ_i* (core); P⁻ (form); then the update points are
///   redrawn from (x⁻, L⁻) or are the χ_i* (SigmaPointRefresh).
/// preview (inputs): γ_i = h(χ_i; x_t, u_t), ẑ, Pzz, S, Pxz, K (core, unscented_transform.hpp);
///   P⁺ and L⁺ (form).
/// commit (z): x⁺ = x⁻ + K (z − ẑ) (core), P⁺ from the preview (form), points from (x⁺, L⁺).

#include <concepts>
#include <cstdint>
#include <string_view>
#include <type_traits>
#include <utility>

#include <fmt/format.h>
#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "twincal/core/eigen.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/options.hpp"
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

/// How a sigma-point filter keeps its covariance, for n-dimensional states and M points: the
/// member policy of SigmaPointFilterCore (StandardCovariance, SquareRootCovariance). The form
/// holds P or L; the buffers of its half of a step are of its types but held by the core's
/// workspace (`w` below, members `propagated`, `mean`, `points`, `factor`, `scratch`, `cache`),
/// which fixes their order (see SigmaPointFilterCore::Workspace).
/// - `Options` (validatable, with a `refresh`), `Initial` (what the constructor starts from),
///   `json_field` (its name in save()); the buffer types `PointBuffers` (n × M, `resize(n, m)`),
///   `FactorBuffers` (`resize(n, m)`), `Scratch` (one posterior, `resize(n)`) and `Cache`;
/// - `require_initial(initial, n)` checks the start before anything is built;
///   `start(options, initial, w)` takes it and returns the lower factor of the first points;
/// - `predict(options, w, covariance_weights, Q, factor)` computes P⁻ from w.propagated and
///   w.mean (and, when `factor`, its lower factor `prior_factor(w)`) into w; `accept_prior(w)`
///   makes it the state;
/// - `prepare(scratch, n)` readies a preview's own scratch; `posterior(options, preview, scratch,
///   R, report)` fills the preview's P⁺ and L⁺ from its K, S, Pxz, Pzz (P⁺ may be skipped when
///   not `report`: update() commits only L⁺); `accept_posterior(preview)` makes it the state;
/// - `stored()` is what save() writes; `read(json, n)` reads and checks it; `assign(value)`.
template <typename F, int N, int M>
concept CovarianceForm = ValidatableOptions<typename F::Options> &&
    std::same_as<std::remove_cvref_t<decltype(std::declval<typename F::Options>().refresh)>,
                 SigmaPointRefresh> && std::default_initializable<F> &&
    requires(F form, const F& const_form, const typename F::Options& options,
             const typename F::Initial& initial, typename F::PointBuffers& point_buffers,
             typename F::FactorBuffers& factor_buffers, typename F::Scratch& scratch,
             MeasurementPreview<N, M>& preview, const nlohmann::json& json, Index n) {
  typename F::Cache;
  { F::json_field } -> std::convertible_to<const char*>;
  point_buffers.resize(n, n);
  factor_buffers.resize(n, n);
  scratch.resize(n);
  F::require_initial(initial, n);
  const_form.prepare(scratch, n);
  const_form.posterior(options, preview, scratch, 1.0, true);
  form.accept_posterior(preview);
  { const_form.stored() } -> std::same_as<const SquareMatrix<N>&>;
  { const_form.read(json, n) } -> std::same_as<SquareMatrix<N>>;
  form.assign(std::declval<SquareMatrix<N>>());
};

/// The shared core of SigmaPointFilter and SquareRootSigmaPointFilter (see the file comment):
/// `Form<N, M>` is the covariance form, held as a member. The filters' documentation applies;
/// errors keep the strong guarantee (the state changes only once nothing can throw).
template <StateModel SM, MeasurementModel MM, SigmaPointScheme Scheme,
          template <int, int> class Form>
requires(SM::dimension_at_compile_time == MM::dimension_at_compile_time) &&
    CovarianceForm<
        Form<SM::dimension_at_compile_time,
             Scheme::points_at_compile_time(SM::dimension_at_compile_time)>,
        SM::dimension_at_compile_time,
        Scheme::points_at_compile_time(SM::dimension_at_compile_time)> class SigmaPointFilterCore {
 public:
  static constexpr int dimension_at_compile_time = SM::dimension_at_compile_time;
  static constexpr int points_at_compile_time =
      Scheme::points_at_compile_time(dimension_at_compile_time);
  using FormType = Form<dimension_at_compile_time, points_at_compile_time>;
  using Options = typename FormType::Options;
  using StateVector = Vector<dimension_at_compile_time>;
  using CovarianceMatrix = SquareMatrix<dimension_at_compile_time>;
  using PointMatrix = Matrix<dimension_at_compile_time, points_at_compile_time>;
  using WeightVector = Vector<points_at_compile_time>;
  using Inputs = typename MM::Inputs;
  using Preview = MeasurementPreview<dimension_at_compile_time, points_at_compile_time>;
  using Record = UpdateRecord<dimension_at_compile_time>;

  /// Checks everything (options, dimensions, finiteness, R > 0, the form's start), computes the
  /// scheme's weights and draws the first points from (x0, the form's factor).
  SigmaPointFilterCore(SM state_model, MM measurement_model, Scheme scheme,
                       const StateVector& initial_state,
                       const typename FormType::Initial& initial_covariance, Options options)
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
    FormType::require_initial(initial_covariance, n);
    require_shape("process_noise", state_model_.process_noise(), n, n);
    require_finite("process_noise", state_model_.process_noise());
    require_finite("noise_variance", measurement_model_.noise_variance());
    require_positive("noise_variance", measurement_model_.noise_variance());

    const Index m = scheme_.num_points(n);
    mean_weights_.resize(m);
    covariance_weights_.resize(m);
    scheme_.weights(n, mean_weights_, covariance_weights_);

    x_ = initial_state;
    points_.resize(n, m);
    workspace_.resize(n, m);
    scheme_.generate(x_, form_.start(options_, initial_covariance, workspace_), points_);
    last_update_.gain = StateVector::Zero(n);
  }

  // --- the filter --------------------------------------------------------------------------

  void predict() {
    const Index n = dimension();
    const auto& process_noise = state_model_.process_noise();
    require_shape("process_noise", process_noise, n, n);
    require_finite("process_noise", process_noise);

    // Into the buffers first: the state changes only once nothing can throw.
    Workspace& w = workspace_;
    propagate_points(state_model_, points_, w.propagated, w.state);
    weighted_mean(w.propagated, mean_weights_, w.mean);
    const bool redraw = options_.refresh == SigmaPointRefresh::redraw;
    form_.predict(options_, w, covariance_weights_, process_noise, redraw);

    if (redraw) {
      scheme_.generate(w.mean, form_.prior_factor(w), points_);
    } else {
      points_.swap(w.propagated);
    }
    x_.swap(w.mean);
    form_.accept_prior(w);
    ++revision_;
  }

  [[nodiscard]] Preview preview(const Inputs& inputs) const {
    Preview p;
    preview(inputs, p);
    return p;
  }

  void preview(const Inputs& inputs, Preview& out) const {
    out.measurements.resize(num_points());
    evaluate_measurements(measurement_model_, points_, inputs, out.measurements);
    preview(out.measurements, out);
  }

  template <typename Derived>
  [[nodiscard]] Preview preview(const Eigen::MatrixBase<Derived>& values) const {
    Preview p;
    preview(values, p);
    return p;
  }

  // A const preview has no kept buffers: it prepares scratch of its own.
  template <typename Derived>
  void preview(const Eigen::MatrixBase<Derived>& values, Preview& out) const {
    typename FormType::Scratch scratch;
    form_.prepare(scratch, dimension());
    fill_preview(values, out, scratch, /*report=*/true);
  }

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
    form_.accept_posterior(preview);
    scheme_.generate(x_, preview.posterior_factor, points_);
    last_update_.innovation = innovation;
    last_update_.innovation_variance = preview.innovation_variance;
    last_update_.gain = preview.gain;
    ++revision_;
    ++updates_;
  }

  // Through the kept preview and scratch: no allocation per step after the first at any size;
  // the form may skip what only a reported preview needs.
  void update(double z, const Inputs& inputs) {
    require_finite("z", z);  // before spending evaluations on a measurement that cannot be used
    Preview& p = workspace_.preview;
    p.measurements.resize(num_points());
    evaluate_measurements(measurement_model_, points_, inputs, p.measurements);
    fill_preview(p.measurements, p, workspace_.scratch, /*report=*/false);
    commit(p, z);
  }

  // --- state ---------------------------------------------------------------------------------

  [[nodiscard]] Index dimension() const noexcept { return x_.size(); }
  [[nodiscard]] Index num_points() const noexcept { return mean_weights_.size(); }
  [[nodiscard]] const StateVector& state() const noexcept { return x_; }
  [[nodiscard]] const PointMatrix& sigma_points() const noexcept { return points_; }
  [[nodiscard]] const WeightVector& mean_weights() const noexcept { return mean_weights_; }
  [[nodiscard]] const WeightVector& covariance_weights() const noexcept {
    return covariance_weights_;
  }
  [[nodiscard]] const Record& last_update() const noexcept { return last_update_; }
  [[nodiscard]] std::uint64_t update_count() const noexcept { return updates_; }
  [[nodiscard]] std::uint64_t revision() const noexcept { return revision_; }
  [[nodiscard]] const SM& state_model() const noexcept { return state_model_; }
  [[nodiscard]] const MM& measurement_model() const noexcept { return measurement_model_; }
  [[nodiscard]] const Scheme& scheme() const noexcept { return scheme_; }
  [[nodiscard]] const Options& options() const noexcept { return options_; }
  [[nodiscard]] const FormType& form() const noexcept { return form_; }

  // --- save / restore ------------------------------------------------------------------------

  /// x, the form's P or L, the update count and the current sigma points (after a predict with
  /// reuse_propagated they are not a function of x and P) under `format`; restores bit-exactly.
  [[nodiscard]] nlohmann::json save(std::string_view format) const {
    nlohmann::json saved;
    saved["format"] = format;
    saved["dimension"] = dimension();
    saved["updates"] = updates_;
    saved["state"] = json_state::vector_to_json(x_);
    saved[FormType::json_field] = json_state::columns_to_json(form_.stored());
    saved["sigma_points"] = json_state::columns_to_json(points_);
    return saved;
  }

  /// Reads and checks everything before changing anything; invalidates previews.
  void restore(const nlohmann::json& saved, std::string_view format) {
    const Index n = dimension();
    json_state::require_header(saved, format, n);
    const std::uint64_t updates = json_state::read_count(saved, "updates");
    StateVector x(n);
    json_state::read_vector(json_state::field(saved, "state"), "state", x);
    CovarianceMatrix stored = form_.read(saved, n);
    PointMatrix points(n, num_points());
    json_state::read_columns(json_state::field(saved, "sigma_points"), "sigma_points", points);

    x_ = x;
    form_.assign(std::move(stored));
    points_ = points;
    updates_ = updates;
    last_update_ = Record{0.0, 0.0, StateVector::Zero(n)};
    ++revision_;
  }

 private:
  // Buffers of predict and update, sized at construction: reused, they make the steps
  // allocation-free at run-time sizes too. Not state: copies and restore() need not match them.
  // The form's buffers (its types) are members here, in this order, as are the core's members
  // below: Eigen's fixed-size matrix-vector products (the predicted mean) round differently with
  // the 16-byte alignment of their output, so the layout is part of the results and is kept.
  struct Workspace {
    void resize(Index n, Index m) {
      propagated.resize(n, m);
      points.resize(n, m);
      state.resize(n);
      mean.resize(n);
      factor.resize(n, m);
      scratch.resize(n);
    }
    PointMatrix propagated;
    typename FormType::PointBuffers points;
    StateVector state;
    StateVector mean;
    typename FormType::FactorBuffers factor;
    typename FormType::Scratch scratch;
    Preview preview;
    [[no_unique_address]] typename FormType::Cache cache;
  };

  // The z-independent update for `values` (may be p.measurements itself) into `p`, with `s` as
  // the form's scratch; P⁺ = L⁺ L⁺ᵀ is needed only when the preview is `report`ed.
  template <typename Derived>
  void fill_preview(const Eigen::MatrixBase<Derived>& values, Preview& p,
                    typename FormType::Scratch& s, bool report) const {
    const double noise_variance = measurement_model_.noise_variance();
    measurement_statistics(points_, x_, mean_weights_, covariance_weights_, values, noise_variance,
                           p);
    form_.posterior(options_, p, s, noise_variance, report);
    p.revision = revision_;
  }

  SM state_model_;
  MM measurement_model_;
  Scheme scheme_;
  Options options_;
  WeightVector mean_weights_;
  WeightVector covariance_weights_;
  StateVector x_;
  FormType form_;  // P or L
  PointMatrix points_;
  Record last_update_;
  Workspace workspace_;
  std::uint64_t updates_ = 0;
  std::uint64_t revision_ = 0;
};

}  // namespace twincal
