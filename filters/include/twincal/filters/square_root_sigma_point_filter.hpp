#pragma once
/// @file
/// `SquareRootSigmaPointFilter<StateModel, MeasurementModel, Scheme>`: the sigma-point filter of
/// SigmaPointFilter carrying the lower Cholesky factor L of P instead of P (van der Merwe and
/// Wan 2001). The factor is propagated with QR decompositions and rank-one Cholesky
/// up/downdates, so P = L Lᵀ is symmetric and positive semi-definite by construction and the
/// representable condition number of P squares (ε² instead of ε).
///
/// predict: L⁻ = R-factor of the stacked [√Wc_i (χ_i* − x⁻)ᵀ (Wc_i > 0); (√Q)ᵀ] (QR),
///   then a rank-one downdate by (χ_i* − x⁻) with weight Wc_i for each negative weight.
/// update (scalar z), with ẑ, S, Pxz, K as in the standard form:
///   - SquareRootUpdate::downdate: L⁺ = cholupdate(L⁻, K√S, −1), the classic form; a downdate
///     that would lose definiteness throws NotPositiveDefiniteError;
///   - SquareRootUpdate::joseph (default): L⁺ = R-factor of [((I − K Hᵀ) L⁻)ᵀ; √R̃ Kᵀ] (QR) with
///     H = P⁻⁻¹ Pxz by two triangular solves and R̃ = R + max(Pzz − Hᵀ P⁻ H, 0), the square root
///     of the Joseph form: equal to P⁻ − K S Kᵀ in exact arithmetic and always positive definite
///     (R > 0), also where the subtraction loses all digits of P⁺.
/// Both agree with the standard form on the reference runs (tests) to 1e-8.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

#include <fmt/format.h>
#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <nlohmann/json.hpp>

#include "twincal/core/cholesky.hpp"
#include "twincal/core/cholesky_factor.hpp"
#include "twincal/core/eigen.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/options.hpp"
#include "twincal/core/validate.hpp"
#include "twincal/filters/filter_state_json.hpp"
#include "twincal/filters/measurement_model.hpp"
#include "twincal/filters/measurement_preview.hpp"
#include "twincal/filters/sigma_point_filter.hpp"
#include "twincal/filters/sigma_point_filter_options.hpp"
#include "twincal/filters/sigma_point_scheme.hpp"
#include "twincal/filters/state_model.hpp"
#include "twincal/filters/unscented_transform.hpp"

namespace twincal {

/// How the square-root filter updates its factor with a measurement.
enum class SquareRootUpdate {
  joseph,    ///< QR of the Joseph form's square root (always positive definite)
  downdate,  ///< rank-one Cholesky downdate by K√S (classic, can fail)
};

struct SquareRootFilterOptions {
  SigmaPointRefresh refresh = SigmaPointRefresh::redraw;
  SquareRootUpdate update = SquareRootUpdate::joseph;

  [[nodiscard]] std::optional<std::string> validate() const {
    return first_problem(
        {rule::check(
             refresh == SigmaPointRefresh::redraw || refresh == SigmaPointRefresh::reuse_propagated,
             "refresh", static_cast<int>(refresh), "must be redraw or reuse_propagated"),
         rule::check(update == SquareRootUpdate::joseph || update == SquareRootUpdate::downdate,
                     "update", static_cast<int>(update), "must be joseph or downdate")});
  }
};

template <StateModel SM, MeasurementModel MM, SigmaPointScheme Scheme>
requires(SM::dimension_at_compile_time ==
         MM::dimension_at_compile_time) class SquareRootSigmaPointFilter {
 public:
  static constexpr int dimension_at_compile_time = SM::dimension_at_compile_time;
  static constexpr int points_at_compile_time =
      Scheme::points_at_compile_time(dimension_at_compile_time);
  using StateVector = Vector<dimension_at_compile_time>;
  using CovarianceMatrix = SquareMatrix<dimension_at_compile_time>;
  using FactorType = CholeskyFactor<dimension_at_compile_time>;
  using PointMatrix = Matrix<dimension_at_compile_time, points_at_compile_time>;
  using WeightVector = Vector<points_at_compile_time>;
  using Inputs = typename MM::Inputs;
  using Preview = MeasurementPreview<dimension_at_compile_time, points_at_compile_time>;
  using Record = UpdateRecord<dimension_at_compile_time>;

  static constexpr std::string_view json_format = "twincal.square_root_sigma_point_filter";

  /// Starts from N(initial_state, L Lᵀ) given the factor L itself, which keeps covariances
  /// whose smallest eigenvalue is below ε·λ_max (they do not survive being formed as L Lᵀ).
  /// @throws as SigmaPointFilter's constructor.
  SquareRootSigmaPointFilter(SM state_model, MM measurement_model, Scheme scheme,
                             const StateVector& initial_state, const FactorType& initial_factor,
                             SquareRootFilterOptions options = {})
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
    require_dimension("initial_factor", initial_factor.dimension(), n);
    require_shape("process_noise", state_model_.process_noise(), n, n);
    require_finite("process_noise", state_model_.process_noise());
    require_finite("noise_variance", measurement_model_.noise_variance());
    require_positive("noise_variance", measurement_model_.noise_variance());

    const Index m = scheme_.num_points(n);
    mean_weights_.resize(m);
    covariance_weights_.resize(m);
    scheme_.weights(n, mean_weights_, covariance_weights_);

    x_ = initial_state;
    L_ = initial_factor.lower();
    points_.resize(n, m);
    workspace_.resize(n, m);
    scheme_.generate(x_, L_, points_);
    last_update_.gain = StateVector::Zero(n);
  }

  /// Starts from N(initial_state, initial_covariance).
  /// @throws as above, and NotPositiveDefiniteError when P0 cannot be factored.
  SquareRootSigmaPointFilter(SM state_model, MM measurement_model, Scheme scheme,
                             const StateVector& initial_state,
                             const CovarianceMatrix& initial_covariance,
                             SquareRootFilterOptions options = {})
      : SquareRootSigmaPointFilter(std::move(state_model), std::move(measurement_model),
                                   std::move(scheme), initial_state, factor_of(initial_covariance),
                                   options) {}

  // --- the filter --------------------------------------------------------------------------

  /// Time update in factored form. √Q is factored once and reused while Q stays the same.
  /// @throws NonFiniteError, DimensionMismatchError, NotPositiveDefiniteError (the factor lost
  ///         definiteness: a negative-weight downdate failed or the stacked matrix is rank
  ///         deficient).
  void predict() {
    const Index n = dimension();
    const Index m = num_points();
    const auto& process_noise = state_model_.process_noise();
    require_shape("process_noise", process_noise, n, n);
    require_finite("process_noise", process_noise);

    // Into the workspace first: the state changes only once nothing can throw.
    Workspace& w = workspace_;
    propagate_points(state_model_, points_, w.propagated, w.state);
    weighted_mean(w.propagated, mean_weights_, w.mean);
    w.centred = w.propagated.colwise() - w.mean;

    // Rows of the stacked matrix whose Gram matrix is P⁻ (negative weights: zero rows, handled
    // by downdates below).
    for (Index i = 0; i < m; ++i) {
      if (covariance_weights_(i) > 0.0) {
        w.stacked.row(i) = std::sqrt(covariance_weights_(i)) * w.centred.col(i).transpose();
      } else {
        w.stacked.row(i).setZero();
      }
    }
    // Fixed-size blocks where the size is known: GCC 12 misreads dynamic blocks of tiny fixed
    // matrices as out of bounds (-Warray-bounds).
    if constexpr (N != Dynamic) {
      w.stacked.template bottomRows<N>() = noise_root_transposed(process_noise);
    } else {
      w.stacked.bottomRows(n) = noise_root_transposed(process_noise);
    }
    w.qr.compute(w.stacked);
    triangular_factor(w.qr, w.factor, "prior factor");
    for (Index i = 0; i < m; ++i) {
      if (covariance_weights_(i) < 0.0) {
        w.update.column = std::sqrt(-covariance_weights_(i)) * w.centred.col(i);
        const Index failed = rank_one_update_in_place(w.factor, w.update.column, -1.0);
        if (failed >= 0) throw_lost_prior_definiteness(process_noise, i, failed);
      }
    }

    if (options_.refresh == SigmaPointRefresh::redraw) {
      scheme_.generate(w.mean, w.factor, points_);
    } else {
      points_.swap(w.propagated);
    }
    x_.swap(w.mean);
    L_.swap(w.factor);
    ++revision_;
  }

  /// As SigmaPointFilter::preview(inputs).
  [[nodiscard]] Preview preview(const Inputs& inputs) const {
    Preview p;
    preview(inputs, p);
    return p;
  }

  /// preview(inputs) into `out` (as SigmaPointFilter's): at fixed sizes it allocates nothing; at
  /// run-time sizes the factored update's scratch is allocated per call. @throws as
  /// preview(inputs); `out` is then unspecified.
  void preview(const Inputs& inputs, Preview& out) const {
    out.measurements.resize(num_points());
    evaluate_measurements(measurement_model_, points_, inputs, out.measurements);
    preview(out.measurements, out);
  }

  /// As SigmaPointFilter::preview(values); the posterior factor comes from the factored update
  /// and posterior_covariance = L⁺ L⁺ᵀ.
  /// @throws DimensionMismatchError, NonFiniteError, NotPositiveDefiniteError.
  template <typename Derived>
  [[nodiscard]] Preview preview(const Eigen::MatrixBase<Derived>& values) const {
    Preview p;
    preview(values, p);
    return p;
  }

  /// preview(values) into `out`. @throws as preview(values); `out` is then unspecified.
  template <typename Derived>
  void preview(const Eigen::MatrixBase<Derived>& values, Preview& out) const {
    UpdateScratch scratch;
    scratch.resize(dimension());
    fill_preview(values, out, scratch, /*form_covariance=*/true);
  }

  /// As SigmaPointFilter::commit.
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
    L_ = preview.posterior_factor;
    scheme_.generate(x_, L_, points_);
    last_update_.innovation = innovation;
    last_update_.innovation_variance = preview.innovation_variance;
    last_update_.gain = preview.gain;
    ++revision_;
    ++updates_;
  }

  /// `commit(preview(inputs), z)` through buffers kept by the filter: no allocation per step
  /// after the first at any size, and P⁺ = L⁺ L⁺ᵀ, which the commit does not need, is not formed.
  void update(double z, const Inputs& inputs) {
    require_finite("z", z);  // before spending evaluations on a measurement that cannot be used
    Preview& p = workspace_.preview;
    p.measurements.resize(num_points());
    evaluate_measurements(measurement_model_, points_, inputs, p.measurements);
    fill_preview(p.measurements, p, workspace_.update, /*form_covariance=*/false);
    commit(p, z);
  }

  // --- state ---------------------------------------------------------------------------------

  [[nodiscard]] Index dimension() const noexcept { return x_.size(); }
  [[nodiscard]] Index num_points() const noexcept { return mean_weights_.size(); }
  [[nodiscard]] const StateVector& state() const noexcept { return x_; }
  /// The lower-triangular factor L (positive diagonal) of the covariance.
  [[nodiscard]] const CovarianceMatrix& factor() const noexcept { return L_; }
  /// P = L Lᵀ.
  [[nodiscard]] CovarianceMatrix covariance() const {
    CovarianceMatrix p(dimension(), dimension());
    p.noalias() = L_ * L_.transpose();
    return p;
  }
  [[nodiscard]] const PointMatrix& sigma_points() const noexcept { return points_; }
  [[nodiscard]] const WeightVector& mean_weights() const noexcept { return mean_weights_; }
  [[nodiscard]] const WeightVector& covariance_weights() const noexcept {
    return covariance_weights_;
  }
  [[nodiscard]] const Record& last_update() const noexcept { return last_update_; }
  [[nodiscard]] std::uint64_t update_count() const noexcept { return updates_; }
  [[nodiscard]] std::uint64_t revision() const noexcept { return revision_; }
  [[nodiscard]] const SquareRootFilterOptions& options() const noexcept { return options_; }
  [[nodiscard]] const SM& state_model() const noexcept { return state_model_; }
  [[nodiscard]] const MM& measurement_model() const noexcept { return measurement_model_; }
  [[nodiscard]] const Scheme& scheme() const noexcept { return scheme_; }

  // --- save / restore ------------------------------------------------------------------------

  /// x, the factor L, the update count and the sigma points as JSON (bit-exact round trip).
  [[nodiscard]] nlohmann::json save() const {
    nlohmann::json saved;
    saved["format"] = json_format;
    saved["dimension"] = dimension();
    saved["updates"] = updates_;
    saved["state"] = json_state::vector_to_json(x_);
    saved["factor"] = json_state::columns_to_json(L_);
    saved["sigma_points"] = json_state::columns_to_json(points_);
    return saved;
  }

  /// Restores a state written by `save()`. @throws as SigmaPointFilter::restore (the factor must
  /// be lower triangular with a positive diagonal) — the filter unchanged.
  void restore(const nlohmann::json& saved) {
    const Index n = dimension();
    json_state::require_header(saved, json_format, n);
    const std::uint64_t updates = json_state::read_count(saved, "updates");
    StateVector x(n);
    json_state::read_vector(json_state::field(saved, "state"), "state", x);
    CovarianceMatrix lower(n, n);
    json_state::read_columns(json_state::field(saved, "factor"), "factor", lower);
    const FactorType checked(lower);  // validates triangularity and the diagonal
    PointMatrix points(n, num_points());
    json_state::read_columns(json_state::field(saved, "sigma_points"), "sigma_points", points);

    x_ = x;
    L_ = checked.lower();
    points_ = points;
    updates_ = updates;
    last_update_ = Record{0.0, 0.0, StateVector::Zero(n)};
    ++revision_;
  }

 private:
  static constexpr int N = dimension_at_compile_time;
  using Stacked = Matrix<size_sum(points_at_compile_time, N), N>;
  using JosephStacked = Matrix<size_sum(N, 1), N>;

  [[nodiscard]] static FactorType factor_of(const CovarianceMatrix& covariance) {
    require_symmetric("initial_covariance", covariance);
    return cholesky(covariance, CholeskyOptions{}, "initial_covariance").factor;
  }

  // Buffers of one factored measurement update (see fill_preview).
  struct UpdateScratch {
    void resize(Index n) {
      column.resize(n);
      whitened.resize(n);
      linearisation.resize(n);
      transition.resize(n, n);
      stacked.resize(n + 1, n);
      qr = Eigen::HouseholderQR<JosephStacked>(n + 1, n);
    }
    StateVector column;
    StateVector whitened;
    StateVector linearisation;
    CovarianceMatrix transition;
    JosephStacked stacked;
    Eigen::HouseholderQR<JosephStacked> qr;
  };

  // Buffers of predict and update, sized at construction: reused, they make the steps
  // allocation-free at run-time sizes too. Not state: copies and restore() need not match them.
  // They also cache √Q, refactored only when the state model's Q changes.
  struct Workspace {
    void resize(Index n, Index m) {
      propagated.resize(n, m);
      centred.resize(n, m);
      state.resize(n);
      mean.resize(n);
      stacked.resize(m + n, n);
      qr = Eigen::HouseholderQR<Stacked>(m + n, n);
      factor.resize(n, n);
      update.resize(n);
      has_noise_root = false;
    }
    PointMatrix propagated;
    PointMatrix centred;
    StateVector state;
    StateVector mean;
    Stacked stacked;
    Eigen::HouseholderQR<Stacked> qr;
    CovarianceMatrix factor;
    UpdateScratch update;
    Preview preview;
    bool has_noise_root = false;
    CovarianceMatrix noise;                  // the Q that noise_root_transposed belongs to
    CovarianceMatrix noise_root_transposed;  // Bᵀ with B Bᵀ = Q
  };

  // Bᵀ for the stacked matrix, with B B^T = Q: the Cholesky factor, or V·√max(Λ, 0) for a
  // singular Q. Cached: a random walk's Q never changes, and re-factoring it was a tenth of a
  // predict at n = 12.
  const CovarianceMatrix& noise_root_transposed(const CovarianceMatrix& q) {
    Workspace& w = workspace_;
    if (w.has_noise_root && w.noise.rows() == q.rows() && w.noise == q) {
      return w.noise_root_transposed;
    }
    const Eigen::LLT<CovarianceMatrix> llt(q);
    if (llt.info() == Eigen::Success && (llt.matrixLLT().diagonal().array() > 0.0).all()) {
      w.noise_root_transposed = llt.matrixU();
    } else {
      const Eigen::SelfAdjointEigenSolver<CovarianceMatrix> eigen(q);
      w.noise_root_transposed =
          (eigen.eigenvectors() * eigen.eigenvalues().cwiseMax(0.0).cwiseSqrt().asDiagonal())
              .transpose();
    }
    w.noise = q;
    w.has_noise_root = true;
    return w.noise_root_transposed;
  }

  // The z-independent factored update for `values` (may be p.measurements itself) into `p`,
  // with `s` as scratch; P⁺ = L⁺ L⁺ᵀ only when asked for (previews, not update()).
  template <typename Derived>
  void fill_preview(const Eigen::MatrixBase<Derived>& values, Preview& p, UpdateScratch& s,
                    bool form_covariance) const {
    const Index n = dimension();
    measurement_statistics(points_, x_, mean_weights_, covariance_weights_, values,
                           measurement_model_.noise_variance(), p);
    if (options_.update == SquareRootUpdate::downdate) {
      p.posterior_factor = L_;
      s.column = std::sqrt(p.innovation_variance) * p.gain;
      const Index failed = rank_one_update_in_place(p.posterior_factor, s.column, -1.0);
      if (failed >= 0) throw_lost_posterior_definiteness(p, failed);
    } else {
      // H = P⁻¹ Pxz = L⁻ᵀ L⁻¹ Pxz; Hᵀ P H = |L⁻¹ Pxz|².
      s.whitened = p.cross_covariance;
      L_.template triangularView<Eigen::Lower>().solveInPlace(s.whitened);
      s.linearisation = s.whitened;
      L_.transpose().template triangularView<Eigen::Upper>().solveInPlace(s.linearisation);
      const double linearisation_error = p.measurement_variance - s.whitened.squaredNorm();
      const double effective_noise =
          measurement_model_.noise_variance() + std::max(linearisation_error, 0.0);
      s.transition.setIdentity();
      s.transition.noalias() -= p.gain * s.linearisation.transpose();
      // ((I − K Hᵀ) L⁻)ᵀ = L⁻ᵀ (I − K Hᵀ)ᵀ
      if constexpr (N != Dynamic) {
        s.stacked.template topRows<N>().noalias() = L_.transpose() * s.transition.transpose();
      } else {
        s.stacked.topRows(n).noalias() = L_.transpose() * s.transition.transpose();
      }
      s.stacked.row(n) = std::sqrt(effective_noise) * p.gain.transpose();
      s.qr.compute(s.stacked);
      triangular_factor(s.qr, p.posterior_factor, "posterior factor");
    }
    if (form_covariance) {
      p.posterior_covariance.noalias() = p.posterior_factor * p.posterior_factor.transpose();
    }
    p.revision = revision_;
  }

  // The lower factor L with L Lᵀ = AᵀA from A's QR (R's rows, signs fixed so diag(L) > 0),
  // into `lower`. @throws NotPositiveDefiniteError (rank deficient), NonFiniteError.
  template <typename QR>
  void triangular_factor(const QR& qr, CovarianceMatrix& lower, std::string_view name) const {
    const Index n = dimension();
    lower = qr.matrixQR().topRows(n).template triangularView<Eigen::Upper>().transpose();
    for (Index k = 0; k < n; ++k) {
      if (lower(k, k) < 0.0) lower.col(k) = -lower.col(k);
      if (!(lower(k, k) > 0.0)) {
        throw NotPositiveDefiniteError(
            std::string(name),
            fmt::format("{}: diagonal entry {} of the QR factor is {}; rule: the stacked square "
                        "roots must have full rank (a positive definite covariance)",
                        name, k, lower(k, k)),
            0.0);
      }
    }
    require_finite(name, lower);
  }

  // Failure paths of the downdates (cold): the covariance the downdate was heading for, and
  // its smallest eigenvalue, say how far from definite it got.
  [[gnu::cold, gnu::noinline, noreturn]] void throw_lost_prior_definiteness(
      const CovarianceMatrix& process_noise, Index point, Index column) const {
    const Workspace& w = workspace_;
    CovarianceMatrix target = process_noise;
    for (Index i = 0; i < num_points(); ++i) {
      target.noalias() +=
          covariance_weights_(i) * (w.centred.col(i) * w.centred.col(i).transpose());
    }
    const double lambda_min = smallest_eigenvalue(target);
    throw NotPositiveDefiniteError(
        "prior factor",
        fmt::format("prior factor: rank-one downdate by sigma point {} (weight {:.6g}) fails at "
                    "column {}: the predicted covariance has smallest eigenvalue {:.6g}; rule: "
                    "it must stay positive definite",
                    point, covariance_weights_(point), column, lambda_min),
        lambda_min);
  }

  [[gnu::cold, gnu::noinline, noreturn]] void throw_lost_posterior_definiteness(
      const Preview& p, Index column) const {
    CovarianceMatrix target = L_ * L_.transpose();
    target.noalias() -= p.innovation_variance * (p.gain * p.gain.transpose());
    const double lambda_min = smallest_eigenvalue(target);
    throw NotPositiveDefiniteError(
        "posterior factor",
        fmt::format("posterior factor: rank-one downdate by K√S fails at column {}: P⁻ − K S Kᵀ "
                    "has smallest eigenvalue {:.6g}; rule: it must stay positive definite (the "
                    "joseph update always does)",
                    column, lambda_min),
        lambda_min);
  }

  SM state_model_;
  MM measurement_model_;
  Scheme scheme_;
  SquareRootFilterOptions options_;
  WeightVector mean_weights_;
  WeightVector covariance_weights_;
  StateVector x_;
  CovarianceMatrix L_;
  PointMatrix points_;
  Record last_update_;
  Workspace workspace_;
  std::uint64_t updates_ = 0;
  std::uint64_t revision_ = 0;
};

}  // namespace twincal
