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
    if (refresh != SigmaPointRefresh::redraw && refresh != SigmaPointRefresh::reuse_propagated) {
      return fmt::format("refresh is {}; it must be redraw or reuse_propagated",
                         static_cast<int>(refresh));
    }
    if (update != SquareRootUpdate::joseph && update != SquareRootUpdate::downdate) {
      return fmt::format("update is {}; it must be joseph or downdate", static_cast<int>(update));
    }
    return std::nullopt;
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

  /// Time update in factored form. @throws NonFiniteError, DimensionMismatchError,
  /// NotPositiveDefiniteError (the factor lost definiteness: a negative-weight downdate failed
  /// or the stacked matrix is rank deficient).
  void predict() {
    const Index n = dimension();
    const Index m = num_points();
    const auto& process_noise = state_model_.process_noise();
    require_shape("process_noise", process_noise, n, n);
    require_finite("process_noise", process_noise);

    PointMatrix propagated(n, m);
    StateVector point(n);
    propagate_points(state_model_, points_, propagated, point);
    StateVector prior_mean(n);
    prior_mean.noalias() = propagated * mean_weights_;
    const PointMatrix centred = propagated.colwise() - prior_mean;

    // Rows of the stacked matrix whose Gram matrix is P⁻ (negative weights: zero rows, handled
    // by downdates below).
    Stacked stacked = Stacked::Zero(m + n, n);
    for (Index i = 0; i < m; ++i) {
      if (covariance_weights_(i) > 0.0) {
        stacked.row(i) = std::sqrt(covariance_weights_(i)) * centred.col(i).transpose();
      }
    }
    // Fixed-size blocks where the size is known: GCC 12 misreads dynamic blocks of tiny fixed
    // matrices as out of bounds (-Warray-bounds).
    if constexpr (N != Dynamic) {
      stacked.template bottomRows<N>() = noise_square_root(process_noise).transpose();
    } else {
      stacked.bottomRows(n) = noise_square_root(process_noise).transpose();
    }
    FactorType factor(triangular_factor(stacked, "prior factor"));
    for (Index i = 0; i < m; ++i) {
      if (covariance_weights_(i) < 0.0)
        factor.rank_one_update(centred.col(i), covariance_weights_(i));
    }

    if (options_.refresh == SigmaPointRefresh::redraw) {
      PointMatrix redrawn(n, m);
      scheme_.generate(prior_mean, factor.lower(), redrawn);
      points_ = redrawn;
    } else {
      points_ = propagated;
    }
    x_ = prior_mean;
    L_ = factor.lower();
    ++revision_;
  }

  /// As SigmaPointFilter::preview(inputs).
  [[nodiscard]] Preview preview(const Inputs& inputs) const {
    WeightVector values(num_points());
    evaluate_measurements(measurement_model_, points_, inputs, values);
    return preview(values);
  }

  /// As SigmaPointFilter::preview(values); the posterior factor comes from the factored update
  /// and posterior_covariance = L⁺ L⁺ᵀ.
  /// @throws DimensionMismatchError, NonFiniteError, NotPositiveDefiniteError.
  template <typename Derived>
  [[nodiscard]] Preview preview(const Eigen::MatrixBase<Derived>& values) const {
    const Index n = dimension();
    Preview p;
    measurement_statistics(points_, x_, mean_weights_, covariance_weights_, values,
                           measurement_model_.noise_variance(), p);
    if (options_.update == SquareRootUpdate::downdate) {
      FactorType factor(L_);
      const StateVector column = p.gain * std::sqrt(p.innovation_variance);
      factor.rank_one_update(column, -1.0);
      p.posterior_factor = factor.lower();
    } else {
      // H = P⁻¹ Pxz = L⁻ᵀ L⁻¹ Pxz; Hᵀ P H = |L⁻¹ Pxz|².
      StateVector whitened = p.cross_covariance;
      L_.template triangularView<Eigen::Lower>().solveInPlace(whitened);
      StateVector h = whitened;
      L_.transpose().template triangularView<Eigen::Upper>().solveInPlace(h);
      const double linearisation = p.measurement_variance - whitened.squaredNorm();
      const double effective_noise =
          measurement_model_.noise_variance() + std::max(linearisation, 0.0);
      CovarianceMatrix a = CovarianceMatrix::Identity(n, n);
      a.noalias() -= p.gain * h.transpose();
      JosephStacked stacked(n + 1, n);
      if constexpr (N != Dynamic) {
        stacked.template topRows<N>().noalias() = (a * L_).transpose();
      } else {
        stacked.topRows(n).noalias() = (a * L_).transpose();
      }
      stacked.row(n) = std::sqrt(effective_noise) * p.gain.transpose();
      p.posterior_factor = triangular_factor(stacked, "posterior factor");
    }
    p.posterior_covariance.noalias() = p.posterior_factor * p.posterior_factor.transpose();
    p.revision = revision_;
    return p;
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
    StateVector posterior_mean = x_;
    posterior_mean.noalias() += preview.gain * innovation;
    require_finite("posterior state", posterior_mean);
    PointMatrix next(dimension(), num_points());
    scheme_.generate(posterior_mean, preview.posterior_factor, next);

    x_ = posterior_mean;
    L_ = preview.posterior_factor;
    points_ = next;
    last_update_.innovation = innovation;
    last_update_.innovation_variance = preview.innovation_variance;
    last_update_.gain = preview.gain;
    ++revision_;
    ++updates_;
  }

  /// `commit(preview(inputs), z)`.
  void update(double z, const Inputs& inputs) {
    require_finite("z", z);
    commit(preview(inputs), z);
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

  // A B with B Bᵀ = Q: the Cholesky factor, or V·√max(Λ, 0) for a singular Q.
  [[nodiscard]] static CovarianceMatrix noise_square_root(const CovarianceMatrix& q) {
    const Eigen::LLT<CovarianceMatrix> llt(q);
    if (llt.info() == Eigen::Success) {
      CovarianceMatrix lower = llt.matrixL();
      if ((lower.diagonal().array() > 0.0).all()) return lower;
    }
    const Eigen::SelfAdjointEigenSolver<CovarianceMatrix> eigen(q);
    CovarianceMatrix root =
        eigen.eigenvectors() * eigen.eigenvalues().cwiseMax(0.0).cwiseSqrt().asDiagonal();
    return root;
  }

  // The lower factor L with L Lᵀ = AᵀA from A's QR (R's rows, signs fixed so diag(L) > 0).
  template <typename Stack>
  [[nodiscard]] CovarianceMatrix triangular_factor(const Stack& stacked,
                                                   std::string_view name) const {
    const Index n = dimension();
    const Eigen::HouseholderQR<Stack> qr(stacked);
    CovarianceMatrix lower =
        qr.matrixQR().topRows(n).template triangularView<Eigen::Upper>().transpose();
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
    return lower;
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
  std::uint64_t updates_ = 0;
  std::uint64_t revision_ = 0;
};

}  // namespace twincal
