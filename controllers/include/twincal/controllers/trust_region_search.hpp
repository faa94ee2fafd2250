#pragma once
/// @file
/// `TrustRegionSearch`: the individualized control u0(x) = argmin_u Q(x, u) (eq. 3) of a twin
/// that is a black box and costs seconds per call, within a budget of evaluations, asked for in
/// batches (a BatchOptimizer).
///
/// A model-based trust-region method on Q²: Q² of an RMS deviation that is affine in u is exactly
/// a quadratic (QuadraticModel), so the model is exact on the linear twins and a local
/// approximation on the others. The first request is the start and 2d points around it (BOBYQA's
/// first 2d + 1 points); then each round
/// 1. fits m(u) = c + 2 gᵀ(u − v) + (u − v)ᵀ H (u − v) to Q² at the evaluated points within twice
///    the radius of the centre v: least squares with H drawn weakly towards the last model's,
///    i.e. the points' own fit where they determine H and the least change of H that fits them
///    where they do not (Powell's least-Frobenius-norm update);
/// 2. minimizes m over the box ∩ the trust region (a box of the radius per locator) with NLopt's
///    bound-constrained L-BFGS, from the centre and from the model's Newton point;
/// 3. asks for the step's end and the d points of the next model around it in one request. The
///    step is kept if it lowers Q² by at least a tenth of what m predicted; the radius then
///    follows the step's length (Powell's rule, as in BOBYQA): max(½, 2‖s‖) times the radius
///    when m predicted three quarters or more of the decrease, max(½, ‖s‖) otherwise (‖s‖ the
///    step's largest component in units of the radius); a rejected step halves it. A point of the
///    request better than the centre becomes the centre.
/// So a round costs d + 1 evaluations and one wait for the twin, where BOBYQA waits once per
/// evaluation. The first radius is a quarter of the box, so the first model sees the quality's
/// trend across kinks and contact rather than its local detail. The search stops when the budget
/// is spent or the radius falls below `final_radius`; the result is the best point evaluated.
///
/// Non-finite qualities mark controls the twin could not evaluate: they are left out of the fits
/// and count as a rejected step. A negative quality is an error (Q is an RMS deviation).

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <new>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>
#include <nlopt.h>
#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/QR>

#include "twincal/controllers/batch_optimizer.hpp"
#include "twincal/controllers/optimizer.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/format.hpp"
#include "twincal/core/options.hpp"
#include "twincal/core/validate.hpp"

namespace twincal {

struct TrustRegionSearchOptions {
  /// Evaluations the search may spend, its starts included.
  std::uint64_t evaluations = 200;
  /// First trust-region radius per locator, as a fraction of the box's width on that locator.
  double initial_radius = 0.25;
  /// The search has converged once the radius is below this fraction of the box's width.
  double final_radius = 1e-4;

  [[nodiscard]] std::optional<std::string> validate() const {
    return first_problem(
        {rule::at_least("evaluations", evaluations, std::uint64_t{1}),
         rule::in_left_open("initial_radius", initial_radius, 0.0, 0.5),
         rule::check(final_radius > 0.0 && final_radius < initial_radius, "final_radius",
                     final_radius, "must lie in (0, initial_radius = {})", initial_radius)});
  }
};

/// How a TrustRegionSearch ended.
enum class TrustRegionStatus {
  converged,     ///< the radius fell below final_radius
  budget_spent,  ///< the evaluations ran out first
};

[[nodiscard]] constexpr std::string_view to_string(TrustRegionStatus status) noexcept {
  return status == TrustRegionStatus::converged ? "converged" : "budget_spent";
}

/// What a TrustRegionSearch found, what it cost and how it ended (Ceres-style summary).
struct TrustRegionSearchResult {
  VectorX argmin;                 ///< the best control evaluated
  double minimum = 0.0;           ///< Q there
  std::uint64_t evaluations = 0;  ///< objective evaluations, starts included
  Index batches = 0;              ///< calls of the batch objective (rounds of the twin's latency)
  Index fits = 0;                 ///< models fitted
  Index accepted_steps = 0;
  double radius = 0.0;  ///< the final radius, as a fraction of the box's width
  TrustRegionStatus status = TrustRegionStatus::budget_spent;
  /// H = ∇²Q²/2 of the last model (QuadraticModel's convention); the one the caller gave, or
  /// zero, if the budget ended before any fit.
  MatrixX curvature;

  /// One line: evaluations, batches, fits, best value, status.
  [[nodiscard]] std::string summary() const {
    return fmt::format(
        "trust region: {} evaluations in {} batches, {} fits, {} steps kept, best {:.10g}, "
        "radius {:.3g} ({})",
        evaluations, batches, fits, accepted_steps, minimum, radius, to_string(status));
  }
};

class TrustRegionSearch {
 public:
  explicit TrustRegionSearch(TrustRegionSearchOptions options = {}) : options_(options) {
    require_valid("TrustRegionSearchOptions", options_);
  }

  [[nodiscard]] const TrustRegionSearchOptions& options() const noexcept { return options_; }

  /// Minimizes Q from `start` over [lower, upper] (lower < upper on every locator).
  /// @throws DimensionMismatchError, NonFiniteError, InvalidArgumentError for inconsistent
  ///         start and bounds or a negative quality; NonFiniteError when no start has a finite
  ///         quality; whatever the objective throws.
  [[nodiscard]] TrustRegionSearchResult minimize(const BatchObjective& objective,
                                                 const VectorX& start, const VectorX& lower,
                                                 const VectorX& upper) const {
    return minimize(objective, start, lower, upper, MatrixX());
  }

  /// As above, with `curvature` (H = ∇²Q²/2, d × d, symmetric; empty for none) as the first
  /// model's H: the first request is then the start and d points, not 2d. For a caller that knows
  /// H, e.g. of a linear twin (one H for every assembly). On the analytic kink twins at d = 12,
  /// H carried over from another assembly's search cost more than it saved (docs/benchmarks.md,
  /// "Budgeted u0"), so the external case does not carry it over.
  [[nodiscard]] TrustRegionSearchResult minimize(const BatchObjective& objective,
                                                 const VectorX& start, const VectorX& lower,
                                                 const VectorX& upper,
                                                 const MatrixX& curvature) const {
    const Index d = start.size();
    require_scaled_search_box(start, lower, upper);
    if (curvature.size() != 0) {
      require_shape("curvature", curvature, d, d);
      require_finite("curvature", curvature);
      require_symmetric("curvature", curvature);
    }
    Run run(objective, options_, lower, upper);
    run.curvature = curvature;
    return run.search(start);
  }

 private:
  // Rounds of one search: the points evaluated so far and the trust region.
  struct Run {
    const BatchObjective& objective;
    const TrustRegionSearchOptions& options;
    const VectorX& lower;
    const VectorX& upper;
    VectorX width;
    Index d;
    Index coefficients;  // 1 + d + d(d + 1)/2 of a quadratic
    MatrixX points;      // d × evaluated
    VectorX squares;     // Q² of each point; NaN where Q was not finite
    TrustRegionSearchResult result;
    MatrixX curvature;  // H of the last model (∇²Q²/2, unscaled): the next fit's prior
    Index best = -1;

    Run(const BatchObjective& f, const TrustRegionSearchOptions& o, const VectorX& l,
        const VectorX& u)
        : objective(f),
          options(o),
          lower(l),
          upper(u),
          width(u - l),
          d(l.size()),
          coefficients(1 + l.size() + l.size() * (l.size() + 1) / 2) {}

    [[nodiscard]] std::uint64_t remaining() const {
      return options.evaluations - result.evaluations;
    }

    TrustRegionSearchResult search(const VectorX& start) {
      double radius = options.initial_radius;
      // The first request: the start and 2d points around it (d where H is given).
      evaluate_with_stencil(start, radius * width, curvature.size() == 0);
      if (best < 0) {
        throw NonFiniteError(
            "quality", fmt::format("quality: the objective answered no finite value at the start "
                                   "{} or around it; rule: the search needs an evaluable start",
                                   start));
      }
      if (curvature.size() == 0) curvature.setZero(d, d);
      Index center = best;
      bool stencil_evaluated = true;  // around the centre at the radius in use
      // A point better than the centre becomes the centre: where Q has kinks a coordinate step
      // can find the descent a smooth model misses.
      const auto recentre = [&] {
        if (best == center) return;
        center = best;
        stencil_evaluated = false;
      };
      result.status = TrustRegionStatus::budget_spent;
      while (remaining() > 0) {
        if (radius < options.final_radius || squares(center) == 0.0) {
          result.status = TrustRegionStatus::converged;
          break;
        }
        const VectorX scale = radius * width;
        const VectorX c = points.col(center);
        const std::optional<Model> model = fit(c, scale, squares(center));
        if (!model) {
          // Too few points near the centre: its stencil, or a smaller radius if it has one.
          if (stencil_evaluated) {
            radius *= 0.5;
            stencil_evaluated = false;
          } else {
            evaluate(stencil(c, scale, false));
            stencil_evaluated = true;
            recentre();
          }
          continue;
        }
        const Step step = minimize_model(*model, c, scale);
        if (!(step.predicted > 1e-12)) {
          // The model sees no descent at this radius: look closer.
          radius *= 0.5;
          stencil_evaluated = false;
          continue;
        }
        const VectorX candidate = c + scale.cwiseProduct(step.s);
        const Index index = evaluate_with_stencil(candidate, scale);
        const double reduction = (squares(center) - squares(index)) / squares(center);
        const double ratio = reduction / step.predicted;
        if (std::isfinite(ratio) && reduction > 0.0 && ratio >= 0.1) {
          center = index;
          ++result.accepted_steps;
          // Powell's rule: the radius follows the step's length, so it shrinks as the steps
          // do and the stencils resolve the quality ever closer to its minimum.
          const double length = step.s.cwiseAbs().maxCoeff();
          radius *= ratio >= 0.75 ? std::max(0.5, 2.0 * length) : std::max(0.5, length);
          radius = std::min(radius, 0.5);
        } else {
          radius *= 0.5;
        }
        stencil_evaluated = center == index;
        recentre();
      }
      result.argmin = points.col(best);
      result.minimum = std::sqrt(squares(best));
      result.radius = radius;
      result.curvature = curvature;
      return result;
    }

    // Evaluates `columns` (one batch), truncated to the budget; returns the first one's index.
    Index evaluate(const MatrixX& columns) {
      const auto count = static_cast<Index>(
          std::min<std::uint64_t>(remaining(), static_cast<std::uint64_t>(columns.cols())));
      const Index first = points.cols();
      if (count == 0) return first;
      VectorX values(count);
      objective(columns.leftCols(count), values);
      points.conservativeResize(d, first + count);
      squares.conservativeResize(first + count);
      points.rightCols(count) = columns.leftCols(count);
      for (Index k = 0; k < count; ++k) {
        const double q = values(k);
        if (std::isfinite(q) && q < 0.0) {
          throw InvalidArgumentError(
              "quality", fmt::format("quality: value is {} at u = {}; rule: a quality (an RMS "
                                     "deviation) must be >= 0",
                                     q, columns.col(k)));
        }
        squares(first + k) = std::isfinite(q) ? q * q : std::numeric_limits<double>::quiet_NaN();
        if (std::isfinite(q) && (best < 0 || q * q < squares(best))) best = first + k;
      }
      result.evaluations += static_cast<std::uint64_t>(count);
      ++result.batches;
      return first;
    }

    // `point` and the d (or 2d) points of the next model around it, in one request.
    Index evaluate_with_stencil(const VectorX& point, const VectorX& scale, bool both = false) {
      const MatrixX around = stencil(point, scale, both);
      MatrixX batch(d, 1 + around.cols());
      batch.col(0) = point;
      batch.rightCols(around.cols()) = around;
      return evaluate(batch);
    }

    // Points around `c` (not c itself): c + σ_i h_i e_i for every locator, σ_i pointing into
    // the box (the radius is at most half the box), and with `both` also the opposite side,
    // or half the step on the same side where the opposite side leaves the box.
    [[nodiscard]] MatrixX stencil(const VectorX& c, const VectorX& h, bool both) const {
      MatrixX out(d, both ? 2 * d : d);
      out.colwise() = c;
      for (Index i = 0; i < d; ++i) {
        const double step = c(i) + h(i) <= upper(i) ? h(i) : -h(i);
        out(i, i) += step;
        if (both) {
          const double opposite = c(i) - step;
          out(i, d + i) =
              opposite >= lower(i) && opposite <= upper(i) ? opposite : c(i) + 0.5 * step;
        }
      }
      return out;
    }

    // m(c + D s) = a + bᵀs + ½ sᵀ M s in the scaled coordinates s = D⁻¹(u − c), in units of
    // Q² at the centre.
    struct Model {
      double a = 0.0;
      VectorX b;
      MatrixX m;

      // m(c + D s) − a, and its gradient b + M s where `gradient` is given.
      [[nodiscard]] double change(const Eigen::Ref<const VectorX>& s,
                                  double* gradient = nullptr) const {
        const VectorX ms = m * s;
        if (gradient != nullptr) Eigen::Map<VectorX>(gradient, s.size()) = b + ms;
        return b.dot(s) + 0.5 * s.dot(ms);
      }
    };

    // Least squares to Q² at the finite points within twice the radius of c, each entry of M
    // also drawn towards the last model's with a small weight (1e-4 against 1 per point): where
    // the points determine M this is their fit (exact for a Q² that is a quadratic), where they
    // do not it is the least change of M that fits them — Powell's least-Frobenius-norm update,
    // which lets 2d + 1 points start a model and each round's d + 1 points refine it. Nothing
    // without d + 1 points.
    std::optional<Model> fit(const VectorX& c, const VectorX& scale, double unit) {
      std::vector<Index> near;
      for (Index k = 0; k < points.cols(); ++k) {
        if (!std::isfinite(squares(k))) continue;
        if (((points.col(k) - c).cwiseQuotient(scale)).cwiseAbs().maxCoeff() <= 2.0 + 1e-12) {
          near.push_back(k);
        }
      }
      const auto n = std::ssize(near);
      if (n < d + 1) return std::nullopt;
      const Index entries = coefficients - 1 - d;
      constexpr double prior_weight = 1e-4;
      const MatrixX prior = 2.0 * scale.asDiagonal() * curvature * scale.asDiagonal() / unit;
      MatrixX design = MatrixX::Zero(n + entries, coefficients);
      VectorX target(n + entries);
      for (Index r = 0; r < n; ++r) {
        const auto k = near[static_cast<std::size_t>(r)];
        const VectorX s = (points.col(k) - c).cwiseQuotient(scale);
        design(r, 0) = 1.0;
        design.row(r).segment(1, d) = s.transpose();
        Index column = 1 + d;
        for (Index i = 0; i < d; ++i) {
          for (Index j = i; j < d; ++j)
            design(r, column++) = i == j ? 0.5 * s(i) * s(i) : s(i) * s(j);
        }
        target(r) = squares(k) / unit;
      }
      Index row = n;
      Index column = 1 + d;
      for (Index i = 0; i < d; ++i) {
        for (Index j = i; j < d; ++j, ++row, ++column) {
          // Off-diagonal entries count twice in ‖M‖_F.
          const double weight = i == j ? prior_weight : prior_weight * std::sqrt(2.0);
          design(row, column) = weight;
          target(row) = weight * prior(i, j);
        }
      }
      const Eigen::ColPivHouseholderQR<MatrixX> qr(design);
      if (qr.rank() < coefficients) return std::nullopt;
      const VectorX solution = qr.solve(target);
      Model model;
      model.a = solution(0);
      model.b = solution.segment(1, d);
      model.m.resize(d, d);
      column = 1 + d;
      for (Index i = 0; i < d; ++i) {
        for (Index j = i; j < d; ++j, ++column) {
          model.m(i, j) = solution(column);
          model.m(j, i) = solution(column);
        }
      }
      curvature = unit * 0.5 * scale.cwiseInverse().asDiagonal() * model.m *
                  scale.cwiseInverse().asDiagonal();
      ++result.fits;
      return model;
    }

    struct Step {
      VectorX s;               // scaled step
      double predicted = 0.0;  // m(0) − m(s)
    };

    // argmin of bᵀs + ½ sᵀ M s over the box ∩ |s_i| ≤ 1, from s = 0 and from the clipped
    // Newton point (or, where M is not positive definite, the clipped steepest descent).
    [[nodiscard]] Step minimize_model(const Model& model, const VectorX& c,
                                      const VectorX& scale) const {
      VectorX low(d);
      VectorX high(d);
      for (Index i = 0; i < d; ++i) {
        low(i) = std::max(-1.0, (lower(i) - c(i)) / scale(i));
        high(i) = std::min(1.0, (upper(i) - c(i)) / scale(i));
      }
      VectorX second(d);
      const Eigen::LLT<MatrixX> llt(model.m);
      if (llt.info() == Eigen::Success) {
        second = -llt.solve(model.b);
      } else {
        const double largest = model.b.cwiseAbs().maxCoeff();
        second = largest > 0.0 ? VectorX(-model.b / largest) : VectorX::Zero(d);
      }
      second = second.cwiseMax(low).cwiseMin(high);
      Step found{VectorX::Zero(d), 0.0};
      for (const VectorX& from : {VectorX(VectorX::Zero(d)), second}) {
        VectorX s = from;
        polish(model, low, high, s);
        const double m = model.change(s);
        if (-m > found.predicted) found = {s, -m};
      }
      return found;
    }

    // L-BFGS with bounds (NLopt) on the model from `s`; keeps `s` where it fails.
    void polish(const Model& model, const VectorX& low, const VectorX& high, VectorX& s) const {
      const auto n = static_cast<unsigned>(d);
      const std::unique_ptr<nlopt_opt_s, decltype(&nlopt_destroy)> opt(
          nlopt_create(NLOPT_LD_LBFGS, n), &nlopt_destroy);
      if (!opt) throw std::bad_alloc();
      nlopt_set_lower_bounds(opt.get(), low.data());
      nlopt_set_upper_bounds(opt.get(), high.data());
      nlopt_set_min_objective(opt.get(), &Run::model_value, const_cast<Model*>(&model));
      nlopt_set_maxeval(opt.get(), static_cast<int>(std::min<Index>(100 * (d + 1), INT_MAX)));
      nlopt_set_xtol_rel(opt.get(), 1e-12);
      VectorX x = s;
      double f = 0.0;
      const nlopt_result code = nlopt_optimize(opt.get(), x.data(), &f);
      if (code > 0 || code == NLOPT_ROUNDOFF_LIMITED) s = x.cwiseMax(low).cwiseMin(high);
    }

    static double model_value(unsigned n, const double* x, double* gradient, void* data) {
      const auto& model = *static_cast<const Model*>(data);
      return model.change(Eigen::Map<const VectorX>(x, static_cast<Index>(n)), gradient);
    }
  };

  TrustRegionSearchOptions options_;
};

static_assert(BatchOptimizer<TrustRegionSearch>);

}  // namespace twincal
