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
///
/// Structure: the filter holds a SigmaPointFilterCore (the models, the scheme, the mean, the
/// points, preview/commit, save/restore: all shared with SigmaPointFilter) with the policy
/// SquareRootCovariance (L, below) as its covariance form.

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
#include <nlohmann/json.hpp>

#include "twincal/core/cholesky.hpp"
#include "twincal/core/cholesky_factor.hpp"
#include "twincal/core/eigen.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/options.hpp"
#include "twincal/core/qr.hpp"
#include "twincal/core/validate.hpp"
#include "twincal/filters/filter_state_json.hpp"
#include "twincal/filters/measurement_model.hpp"
#include "twincal/filters/measurement_preview.hpp"
#include "twincal/filters/sigma_point_filter.hpp"
#include "twincal/filters/sigma_point_filter_core.hpp"
#include "twincal/filters/sigma_point_filter_options.hpp"
#include "twincal/filters/sigma_point_scheme.hpp"
#include "twincal/filters/state_model.hpp"

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

/// The covariance form (CovarianceForm) of SquareRootSigmaPointFilter: keeps the lower Cholesky
/// factor L of P (positive diagonal), updated by QR decompositions and rank-one downdates
/// (see the file comment), never forming P on the way.
template <int N, int M>
class SquareRootCovariance {
  using Stacked = Matrix<size_sum(M, N), N>;
  using JosephStacked = Matrix<size_sum(N, 1), N>;

 public:
  using Options = SquareRootFilterOptions;
  using Initial = CholeskyFactor<N>;
  using CovarianceMatrix = SquareMatrix<N>;
  using StateVector = Vector<N>;
  using PointMatrix = Matrix<N, M>;
  using WeightVector = Vector<M>;
  using Preview = MeasurementPreview<N, M>;

  static constexpr const char* json_field = "factor";

  // The centred propagated points.
  struct PointBuffers {
    void resize(Index n, Index m) { centred.resize(n, m); }
    PointMatrix centred;
  };

  // The stacked square roots of P⁻, their QR and L⁻.
  struct FactorBuffers {
    void resize(Index n, Index m) {
      stacked.resize(m + n, n);
      qr = Eigen::HouseholderQR<Stacked>(m + n, n);
      factor.resize(n, n);
    }
    Stacked stacked;
    Eigen::HouseholderQR<Stacked> qr;
    CovarianceMatrix factor;
  };

  // Buffers of one factored measurement update (see posterior); predict's downdates use
  // `column` too.
  struct Scratch {
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

  // √Q, refactored only when the state model's Q changes (a random walk's never does, and
  // re-factoring it was a tenth of a predict at n = 12).
  struct Cache {
    bool has_noise_root = false;
    CovarianceMatrix noise;                  // the Q that noise_root_transposed belongs to
    CovarianceMatrix noise_root_transposed;  // Bᵀ with B Bᵀ = Q
  };

  [[nodiscard]] const CovarianceMatrix& factor() const noexcept { return L_; }

  static void require_initial(const Initial& initial_factor, Index n) {
    require_dimension("initial_factor", initial_factor.dimension(), n);
  }

  template <typename Workspace>
  [[nodiscard]] const CovarianceMatrix& start(const Options& /*options*/,
                                              const Initial& initial_factor, Workspace& /*w*/) {
    L_ = initial_factor.lower();
    return L_;
  }

  // L⁻ into w.factor in factored form (always: it is the prior itself).
  template <typename Workspace, EigenMatrixOfShape<N, N> Noise>
  void predict(const Options& /*options*/, Workspace& w, const WeightVector& covariance_weights,
               const Noise& process_noise, bool /*factor*/) const {
    const Index n = L_.rows();
    const Index m = covariance_weights.size();
    PointMatrix& centred = w.points.centred;
    FactorBuffers& f = w.factor;
    centred = w.propagated.colwise() - w.mean;

    // Rows of the stacked matrix whose Gram matrix is P⁻ (negative weights: zero rows, handled
    // by downdates below).
    for (Index i = 0; i < m; ++i) {
      if (covariance_weights(i) > 0.0) {
        f.stacked.row(i) = std::sqrt(covariance_weights(i)) * centred.col(i).transpose();
      } else {
        f.stacked.row(i).setZero();
      }
    }
    // Fixed-size blocks where the size is known: GCC 12 misreads dynamic blocks of tiny fixed
    // matrices as out of bounds (-Warray-bounds).
    if constexpr (N != Dynamic) {
      f.stacked.template bottomRows<N>() = noise_root_transposed(w.cache, process_noise);
    } else {
      f.stacked.bottomRows(n) = noise_root_transposed(w.cache, process_noise);
    }
    f.qr.compute(f.stacked);
    triangular_factor(f.qr, f.factor, "prior factor");
    for (Index i = 0; i < m; ++i) {
      if (covariance_weights(i) < 0.0) {
        w.scratch.column = std::sqrt(-covariance_weights(i)) * centred.col(i);
        const Index failed = rank_one_update_in_place(f.factor, w.scratch.column, -1.0);
        if (failed >= 0) {
          throw_lost_prior_definiteness(process_noise, centred, covariance_weights, i, failed);
        }
      }
    }
  }
  template <typename Workspace>
  [[nodiscard]] const CovarianceMatrix& prior_factor(const Workspace& w) const noexcept {
    return w.factor.factor;
  }
  template <typename Workspace>
  void accept_prior(Workspace& w) noexcept {
    L_.swap(w.factor.factor);
  }

  // A const preview's scratch is its own, sized here (allocating at run-time sizes).
  void prepare(Scratch& scratch, Index n) const { scratch.resize(n); }

  // The factored update into p.posterior_factor; P⁺ = L⁺ L⁺ᵀ only when `report`ed (previews,
  // not update(), whose commit needs only L⁺).
  void posterior(const Options& options, Preview& p, Scratch& s, double noise_variance,
                 bool report) const {
    const Index n = L_.rows();
    if (options.update == SquareRootUpdate::downdate) {
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
      const double effective_noise = noise_variance + std::max(linearisation_error, 0.0);
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
    if (report) {
      p.posterior_covariance.noalias() = p.posterior_factor * p.posterior_factor.transpose();
    }
  }
  void accept_posterior(const Preview& p) { L_ = p.posterior_factor; }

  [[nodiscard]] const CovarianceMatrix& stored() const noexcept { return L_; }
  [[nodiscard]] static CovarianceMatrix read(const nlohmann::json& saved, Index n) {
    CovarianceMatrix lower(n, n);
    json_state::read_columns(json_state::field(saved, "factor"), "factor", lower);
    const CholeskyFactor<N> checked(lower);  // validates triangularity and the diagonal
    return checked.lower();
  }
  void assign(CovarianceMatrix value) { L_ = std::move(value); }

 private:
  // Bᵀ for the stacked matrix, with B B^T = Q: the Cholesky factor, or V·√max(Λ, 0) for a
  // singular Q; kept in `cache` while Q stays the same.
  static const CovarianceMatrix& noise_root_transposed(Cache& cache, const CovarianceMatrix& q) {
    if (cache.has_noise_root && cache.noise.rows() == q.rows() && cache.noise == q) {
      return cache.noise_root_transposed;
    }
    const Eigen::LLT<CovarianceMatrix> llt(q);
    if (llt.info() == Eigen::Success && (llt.matrixLLT().diagonal().array() > 0.0).all()) {
      cache.noise_root_transposed = llt.matrixU();
    } else {
      const Eigen::SelfAdjointEigenSolver<CovarianceMatrix> eigen(q);
      cache.noise_root_transposed =
          (eigen.eigenvectors() * eigen.eigenvalues().cwiseMax(0.0).cwiseSqrt().asDiagonal())
              .transpose();
    }
    cache.noise = q;
    cache.has_noise_root = true;
    return cache.noise_root_transposed;
  }

  // The lower factor L with L Lᵀ = AᵀA from A's QR (R's rows, signs fixed so diag(L) > 0),
  // into `lower`. @throws NotPositiveDefiniteError (rank deficient), NonFiniteError.
  template <typename QR>
  void triangular_factor(const QR& qr, CovarianceMatrix& lower, std::string_view name) const {
    const Index n = L_.rows();
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
  [[gnu::cold, gnu::noinline, noreturn]] static void throw_lost_prior_definiteness(
      const CovarianceMatrix& process_noise, const PointMatrix& centred,
      const WeightVector& covariance_weights, Index point, Index column) {
    CovarianceMatrix target = process_noise;
    for (Index i = 0; i < covariance_weights.size(); ++i) {
      target.noalias() += covariance_weights(i) * (centred.col(i) * centred.col(i).transpose());
    }
    const double lambda_min = smallest_eigenvalue(target);
    throw NotPositiveDefiniteError(
        "prior factor",
        fmt::format("prior factor: rank-one downdate by sigma point {} (weight {:.6g}) fails at "
                    "column {}: the predicted covariance has smallest eigenvalue {:.6g}; rule: "
                    "it must stay positive definite",
                    point, covariance_weights(point), column, lambda_min),
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

  CovarianceMatrix L_;
};

template <StateModel SM, MeasurementModel MM, SigmaPointScheme Scheme>
requires(SM::dimension_at_compile_time ==
         MM::dimension_at_compile_time) class SquareRootSigmaPointFilter {
  using Core = SigmaPointFilterCore<SM, MM, Scheme, SquareRootCovariance>;

 public:
  static constexpr int dimension_at_compile_time = Core::dimension_at_compile_time;
  static constexpr int points_at_compile_time = Core::points_at_compile_time;
  using StateVector = typename Core::StateVector;
  using CovarianceMatrix = typename Core::CovarianceMatrix;
  using FactorType = CholeskyFactor<dimension_at_compile_time>;
  using PointMatrix = typename Core::PointMatrix;
  using WeightVector = typename Core::WeightVector;
  using Inputs = typename Core::Inputs;
  using Preview = typename Core::Preview;
  using Record = typename Core::Record;

  static constexpr std::string_view json_format = "twincal.square_root_sigma_point_filter";

  /// Starts from N(initial_state, L Lᵀ) given the factor L itself, which keeps covariances
  /// whose smallest eigenvalue is below ε·λ_max (they do not survive being formed as L Lᵀ).
  /// @throws as SigmaPointFilter's constructor.
  SquareRootSigmaPointFilter(SM state_model, MM measurement_model, Scheme scheme,
                             const StateVector& initial_state, const FactorType& initial_factor,
                             SquareRootFilterOptions options = {})
      : core_(std::move(state_model), std::move(measurement_model), std::move(scheme),
              initial_state, initial_factor, options) {}

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

  /// Time update in factored form (the file comment). √Q is factored once and reused while Q
  /// stays the same.
  /// @throws NonFiniteError, DimensionMismatchError, NotPositiveDefiniteError (the factor lost
  ///         definiteness: a negative-weight downdate failed or the stacked matrix is rank
  ///         deficient).
  void predict() { core_.predict(); }

  /// As SigmaPointFilter::preview(inputs).
  [[nodiscard]] Preview preview(const Inputs& inputs) const { return core_.preview(inputs); }

  /// preview(inputs) into `out` (as SigmaPointFilter's): at fixed sizes it allocates nothing; at
  /// run-time sizes the factored update's scratch is allocated per call. @throws as
  /// preview(inputs); `out` is then unspecified.
  void preview(const Inputs& inputs, Preview& out) const { core_.preview(inputs, out); }

  /// As SigmaPointFilter::preview(values); the posterior factor comes from the factored update
  /// and posterior_covariance = L⁺ L⁺ᵀ.
  /// @throws DimensionMismatchError, NonFiniteError, NotPositiveDefiniteError.
  template <typename Derived>
  [[nodiscard]] Preview preview(const Eigen::MatrixBase<Derived>& values) const {
    return core_.preview(values);
  }

  /// preview(values) into `out`. @throws as preview(values); `out` is then unspecified.
  template <typename Derived>
  void preview(const Eigen::MatrixBase<Derived>& values, Preview& out) const {
    core_.preview(values, out);
  }

  /// As SigmaPointFilter::commit.
  void commit(const Preview& preview, double z) { core_.commit(preview, z); }

  /// `commit(preview(inputs), z)` through buffers kept by the filter: no allocation per step
  /// after the first at any size, and P⁺ = L⁺ L⁺ᵀ, which the commit does not need, is not formed.
  void update(double z, const Inputs& inputs) { core_.update(z, inputs); }

  // --- state ---------------------------------------------------------------------------------

  [[nodiscard]] Index dimension() const noexcept { return core_.dimension(); }
  [[nodiscard]] Index num_points() const noexcept { return core_.num_points(); }
  [[nodiscard]] const StateVector& state() const noexcept { return core_.state(); }
  /// The lower-triangular factor L (positive diagonal) of the covariance.
  [[nodiscard]] const CovarianceMatrix& factor() const noexcept { return core_.form().factor(); }
  /// P = L Lᵀ.
  [[nodiscard]] CovarianceMatrix covariance() const {
    const CovarianceMatrix& lower = factor();
    CovarianceMatrix p(dimension(), dimension());
    p.noalias() = lower * lower.transpose();
    return p;
  }
  [[nodiscard]] const PointMatrix& sigma_points() const noexcept { return core_.sigma_points(); }
  [[nodiscard]] const WeightVector& mean_weights() const noexcept { return core_.mean_weights(); }
  [[nodiscard]] const WeightVector& covariance_weights() const noexcept {
    return core_.covariance_weights();
  }
  [[nodiscard]] const Record& last_update() const noexcept { return core_.last_update(); }
  [[nodiscard]] std::uint64_t update_count() const noexcept { return core_.update_count(); }
  [[nodiscard]] std::uint64_t revision() const noexcept { return core_.revision(); }
  [[nodiscard]] const SquareRootFilterOptions& options() const noexcept { return core_.options(); }
  [[nodiscard]] const SM& state_model() const noexcept { return core_.state_model(); }
  [[nodiscard]] const MM& measurement_model() const noexcept { return core_.measurement_model(); }
  [[nodiscard]] const Scheme& scheme() const noexcept { return core_.scheme(); }

  // --- save / restore ------------------------------------------------------------------------

  /// x, the factor L, the update count and the sigma points as JSON (bit-exact round trip).
  [[nodiscard]] nlohmann::json save() const { return core_.save(json_format); }

  /// Restores a state written by `save()`. @throws as SigmaPointFilter::restore (the factor must
  /// be lower triangular with a positive diagonal) — the filter unchanged.
  void restore(const nlohmann::json& saved) { core_.restore(saved, json_format); }

 private:
  [[nodiscard]] static FactorType factor_of(const CovarianceMatrix& covariance) {
    require_symmetric("initial_covariance", covariance);
    return cholesky(covariance, CholeskyOptions{}, "initial_covariance").factor;
  }

  Core core_;
};

}  // namespace twincal
