#pragma once
/// @file
/// `LeastSquaresSearch`: the individualized control u0(x) = argmin_u Q(x, u) (eq. 3) of a twin
/// that answers its key points' deviations r(x, u), Q = ‖r‖ / √m (TwinWithDeviations), within a
/// budget of evaluations asked for in batches.
///
/// Eq. (3) is then a nonlinear least-squares problem, min ‖r(u)‖², and Levenberg–Marquardt
/// solves it: each round forms the Jacobian J of r at the centre by forward differences (d points
/// in one request), takes the step s that minimizes ‖r + J s‖² + μ sᵀ diag(JᵀJ) s over the box
/// (core's bounded_least_squares: a projected step stalls where the optimum has locators at their
/// bounds, as the door's does), and asks for the step's end (one point). A step that lowers ‖r‖² is
/// kept and μ falls by 3; otherwise μ grows by 4 and the step is tried again from the same J. The
/// Jacobian of the deviations sees which contacts are closed and which side of each active set the
/// point is on, so the step crosses the kinks of Q that stall a model of Q² alone
/// (TrustRegionSearch; docs/benchmarks.md, "Budgeted u0"). The difference step is a hundredth of
/// the box by default, wide enough that J averages over the kinks next to the point rather than
/// reporting one side of them.
///
/// A local search ends when its step is below `final_step` of the box on every locator or μ
/// passes `max_damping` (no step of any length lowers ‖r‖² along the model's directions: a
/// minimum or a kink). Contact makes eq. (3) multimodal (a gap that closes moves the optimum by a
/// jump), so while the budget allows another local search it restarts from the best point so far
/// moved by N(0, (restart_spread · width)²) per locator, drawn from the caller's RandomStream
/// (or until `agreeing_restarts` in a row have come back to the best minimum).
/// The result is the best point evaluated.
///
/// Evaluations: 1 per start, d per Jacobian, 1 per trial step, each its own request. With
/// `speculative_jacobian` a start and each trial step come with the Jacobian's stencil at their
/// point in one request of d + 1: a step kept needs no request of its own for its Jacobian, a
/// step rejected has spent d evaluations for nothing. Non-finite deviations mark a
/// control the twin could not evaluate: a trial step there is rejected, a Jacobian with one ends
/// that local search. Its workspace is allocated once per call to minimize; each step's
/// bounded_least_squares allocates its own (one step per request to the twin).

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <string_view>

#include <fmt/format.h>
#include <Eigen/Core>

#include "twincal/controllers/optimizer.hpp"
#include "twincal/core/bounded_least_squares.hpp"
#include "twincal/core/eigen.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/format.hpp"
#include "twincal/core/options.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/core/validate.hpp"

namespace twincal {

/// r at each column of `points` into the columns of `deviations` (m × k); may throw (the search
/// passes the error on unchanged). A non-finite entry marks a point the twin could not evaluate.
using DeviationObjective =
    std::function<void(const Eigen::Ref<const MatrixX>& points, Eigen::Ref<MatrixX> deviations)>;

struct LeastSquaresSearchOptions {
  /// Evaluations the search may spend, its starts included.
  std::uint64_t evaluations = 200;
  /// Forward-difference step of the Jacobian per locator, as a fraction of the box's width.
  double difference_step = 0.01;
  /// A restart moves the best point by N(0, (restart_spread · width)²) per locator; 0: one local
  /// search only.
  double restart_spread = 0.1;
  /// The search stops once this many restarts in a row have ended at the best minimum again
  /// (within `agreement` of its ‖r‖²), so a twin with one basin, such as a linear one, stops
  /// before its budget; 0: restarts spend the budget. Off by default: restarts that return to
  /// one basin several times in a row can still find a better one (docs/benchmarks.md, "Budgeted
  /// u0": 3 cut the door's calls by two thirds and missed a better basin on a fifth of a 2-locator
  /// contact twin's assemblies).
  Index agreeing_restarts = 0;
  /// Relative difference of ‖r‖² within which a local search's end is the best minimum again.
  double agreement = 1e-6;
  /// A local search has converged once its step is below this fraction of the box's width on
  /// every locator.
  double final_step = 1e-8;
  /// Ask for the Jacobian's stencil at a start or a trial step in the same request as the point
  /// (d + 1 points): a half to a third of the requests, at d wasted evaluations per rejected
  /// step. For a twin whose requests cost more than their points (a pool of workers that
  /// evaluates a request's points side by side); the budget then buys fewer local searches and
  /// finds z* within 1 % less often at d = 12 on contact and kinks (docs/benchmarks.md,
  /// "Speculative Jacobians").
  bool speculative_jacobian = false;
  /// μ of each local search's first step (relative to diag(JᵀJ)).
  double initial_damping = 1e-3;
  /// A local search has stalled once μ exceeds this.
  double max_damping = 1e8;

  [[nodiscard]] std::optional<std::string> validate() const {
    return first_problem(
        {rule::at_least("evaluations", evaluations, std::uint64_t{1}),
         rule::in_left_open("difference_step", difference_step, 0.0, 0.5),
         rule::non_negative_finite("restart_spread", restart_spread),
         rule::at_least("agreeing_restarts", agreeing_restarts, Index{0}),
         rule::in_left_open("agreement", agreement, 0.0, 1.0),
         rule::in_left_open("final_step", final_step, 0.0, 1.0),
         rule::positive_finite("initial_damping", initial_damping),
         rule::check(max_damping > initial_damping && std::isfinite(max_damping), "max_damping",
                     max_damping, "must be finite and > initial_damping = {}", initial_damping)});
  }
};

/// How a LeastSquaresSearch's last local search ended.
enum class LeastSquaresStatus {
  converged,     ///< its step fell below final_step, or μ passed max_damping
  budget_spent,  ///< the evaluations ran out first
};

[[nodiscard]] constexpr std::string_view to_string(LeastSquaresStatus status) noexcept {
  return status == LeastSquaresStatus::converged ? "converged" : "budget_spent";
}

/// What a LeastSquaresSearch found, what it cost and how it ended (Ceres-style summary).
struct LeastSquaresSearchResult {
  VectorX argmin;                 ///< the best control evaluated
  double minimum = 0.0;           ///< Q = ‖r‖ / √m there
  std::uint64_t evaluations = 0;  ///< deviation evaluations (points), starts included
  Index batches = 0;              ///< calls of the objective (rounds of the twin's latency)
  Index local_searches = 0;       ///< the first and every restart
  Index jacobians = 0;
  Index accepted_steps = 0;
  LeastSquaresStatus status = LeastSquaresStatus::budget_spent;

  /// One line: evaluations, batches, local searches, best value, status.
  [[nodiscard]] std::string summary() const {
    return fmt::format(
        "least squares: {} evaluations in {} batches, {} local searches, {} Jacobians, {} steps "
        "kept, best {:.10g} ({})",
        evaluations, batches, local_searches, jacobians, accepted_steps, minimum,
        to_string(status));
  }
};

class LeastSquaresSearch {
 public:
  explicit LeastSquaresSearch(LeastSquaresSearchOptions options = {}) : options_(options) {
    require_valid("LeastSquaresSearchOptions", options_);
  }

  [[nodiscard]] const LeastSquaresSearchOptions& options() const noexcept { return options_; }

  /// Minimizes ‖r‖ from `start` over [lower, upper] (lower < upper on every locator), r having
  /// `key_points` entries; restarts draw from `restarts` (record its seed with the result).
  /// @throws DimensionMismatchError, NonFiniteError, InvalidArgumentError for inconsistent start,
  ///         bounds or key_points; NonFiniteError when the start's deviations are not finite;
  ///         whatever the objective throws.
  [[nodiscard]] LeastSquaresSearchResult minimize(const DeviationObjective& objective,
                                                  Index key_points, const VectorX& start,
                                                  const VectorX& lower, const VectorX& upper,
                                                  RandomStream restarts) const {
    require_scaled_search_box(start, lower, upper);
    if (key_points < 1) {
      throw InvalidArgumentError(
          "key_points", fmt::format("key_points: value is {}; rule: must be >= 1", key_points));
    }
    Run run(objective, options_, key_points, lower, upper);
    return run.search(start, restarts);
  }

 private:
  // One search: its workspace and what it has spent.
  struct Run {
    const DeviationObjective& objective;
    const LeastSquaresSearchOptions& options;
    const VectorX& lower;
    const VectorX& upper;
    Index d;
    VectorX width;
    VectorX center;
    VectorX residual;            // r at the centre
    double cost = 0.0;           // ‖r‖² at the centre
    MatrixX jacobian;            // m × d
    MatrixX stencil;             // d × d, the Jacobian's points
    VectorX steps;               // the Jacobian's difference per locator (signed)
    VectorX draw;                // a restart's N(0, I)
    MatrixX stencil_deviations;  // m × d
    VectorX trial;
    MatrixX trial_deviations;  // m × 1
    MatrixX joint;             // d × (d + 1): a point and its stencil (speculative_jacobian)
    MatrixX joint_deviations;  // m × (d + 1)
    VectorX scale;             // diag(JᵀJ), floored
    MatrixX damped;            // [J; √μ diag(scale)^½]: the step's least-squares problem
    VectorX damped_residual;   // [r; 0]
    VectorX step_lower;        // lower − centre
    VectorX step_upper;        // upper − centre
    VectorX best;
    double best_cost = std::numeric_limits<double>::infinity();
    LeastSquaresSearchResult result;

    Run(const DeviationObjective& f, const LeastSquaresSearchOptions& o, Index m, const VectorX& l,
        const VectorX& u)
        : objective(f),
          options(o),
          lower(l),
          upper(u),
          d(l.size()),
          width(u - l),
          center(l.size()),
          residual(m),
          jacobian(m, l.size()),
          stencil(l.size(), l.size()),
          steps(l.size()),
          draw(l.size()),
          stencil_deviations(m, l.size()),
          trial(l.size()),
          trial_deviations(m, 1),
          joint(l.size(), o.speculative_jacobian ? l.size() + 1 : 0),
          joint_deviations(m, o.speculative_jacobian ? l.size() + 1 : 0),
          scale(l.size()),
          damped(m + l.size(), l.size()),
          damped_residual(VectorX::Zero(m + l.size())),
          step_lower(l.size()),
          step_upper(l.size()),
          best(l.size()) {}

    [[nodiscard]] std::uint64_t remaining() const {
      return options.evaluations - result.evaluations;
    }
    [[nodiscard]] std::uint64_t dimension() const { return static_cast<std::uint64_t>(d); }

    // ‖r(point)‖² (infinity where r is not finite), r into trial_deviations; one request.
    double evaluate(const VectorX& point) {
      objective(point, trial_deviations);
      ++result.batches;
      ++result.evaluations;
      keep_best(Eigen::Map<const MatrixX>(point.data(), d, 1), trial_deviations);
      return finite_cost(trial_deviations.col(0));
    }

    // Whether the point and its Jacobian's stencil go in one request (speculative_jacobian):
    // while the budget holds them both.
    [[nodiscard]] bool speculate() const {
      return options.speculative_jacobian && remaining() >= dimension() + 1;
    }

    // evaluate() with the Jacobian's stencil at `point` in the same request: r into
    // trial_deviations, the stencil's deviations into joint_deviations' last d columns for
    // take_jacobian().
    double evaluate_with_stencil(const VectorX& point) {
      joint.col(0) = point;
      place_stencil(point, joint.rightCols(d));
      objective(joint, joint_deviations);
      ++result.batches;
      result.evaluations += dimension() + 1;
      keep_best(joint, joint_deviations);
      trial_deviations = joint_deviations.leftCols(1);
      return finite_cost(trial_deviations.col(0));
    }

    [[nodiscard]] static double finite_cost(const Eigen::Ref<const VectorX>& deviations) {
      const double value = deviations.squaredNorm();
      return std::isfinite(value) ? value : std::numeric_limits<double>::infinity();
    }

    // The best of a request's points so far (non-finite deviations never are).
    void keep_best(const Eigen::Ref<const MatrixX>& points,
                   const Eigen::Ref<const MatrixX>& deviations) {
      for (Index j = 0; j < points.cols(); ++j) {
        const double value = deviations.col(j).squaredNorm();
        if (std::isfinite(value) && value < best_cost) {
          best_cost = value;
          best = points.col(j);
        }
      }
    }

    LeastSquaresSearchResult search(const VectorX& start, RandomStream& restarts) {
      // The start, then local searches while one more could take a step (a start, a Jacobian and
      // a trial).
      result.status = local_search(start);
      if (!std::isfinite(best_cost)) {
        throw NonFiniteError(
            "deviations",
            fmt::format("deviations: the objective answered non-finite deviations at the start "
                        "{}; rule: the search needs an evaluable start",
                        start));
      }
      Index agreeing = 0;
      while (options.restart_spread > 0.0 && remaining() >= dimension() + 2 &&
             (options.agreeing_restarts == 0 || agreeing < options.agreeing_restarts)) {
        restarts.fill_normal(draw);
        trial = (best + options.restart_spread * width.cwiseProduct(draw))
                    .cwiseMax(lower)
                    .cwiseMin(upper);
        const double before = best_cost;
        result.status = local_search(trial);
        const bool again = best_cost >= before * (1.0 - options.agreement) &&
                           cost <= before * (1.0 + options.agreement);
        agreeing = again ? agreeing + 1 : 0;
      }
      result.argmin = best;
      result.minimum = std::sqrt(best_cost / static_cast<double>(residual.size()));
      return result;
    }

    // Levenberg–Marquardt from `from` until it converges, stalls or the budget ends.
    LeastSquaresStatus local_search(const VectorX& from) {
      ++result.local_searches;
      center = from;  // `from` may be `trial`, which evaluate() leaves alone
      const bool speculated = speculate();
      cost = speculated ? evaluate_with_stencil(center) : evaluate(center);
      if (!std::isfinite(cost)) return LeastSquaresStatus::converged;  // nothing to descend from
      residual = trial_deviations.col(0);
      if (speculated && !take_jacobian(joint_deviations.rightCols(d))) {
        return LeastSquaresStatus::converged;
      }
      double damping = options.initial_damping;
      bool jacobian_current = speculated;
      while (true) {
        if (cost == 0.0) return LeastSquaresStatus::converged;
        if (!jacobian_current) {
          if (remaining() < dimension() + 1) return LeastSquaresStatus::budget_spent;
          if (!differentiate()) return LeastSquaresStatus::converged;
          jacobian_current = true;
        }
        if (remaining() < 1) return LeastSquaresStatus::budget_spent;
        // Marquardt's scaling, with a floor so that a locator r does not see gets a damped
        // (zero) step instead of a singular system.
        const Index m = residual.size();
        damped.topRows(m) = jacobian;
        damped.bottomRows(d).setZero();
        damped.bottomRows(d).diagonal() = (damping * scale).cwiseSqrt();
        damped_residual.head(m) = residual;
        step_lower = lower - center;
        step_upper = upper - center;
        trial = center +
                bounded_least_squares(damped, damped_residual, step_lower, step_upper).solution;
        trial = trial.cwiseMax(lower).cwiseMin(upper);  // round-off
        if (((trial - center).cwiseAbs().array() <= options.final_step * width.array()).all())
          return LeastSquaresStatus::converged;
        const bool speculative = speculate();
        const double value = speculative ? evaluate_with_stencil(trial) : evaluate(trial);
        if (value < cost) {
          center = trial;
          cost = value;
          residual = trial_deviations.col(0);
          damping = std::max(damping / 3.0, 1e-12);
          ++result.accepted_steps;
          jacobian_current = speculative;
          if (speculative && !take_jacobian(joint_deviations.rightCols(d))) {
            return LeastSquaresStatus::converged;
          }
        } else {
          damping *= 4.0;
          if (damping > options.max_damping) return LeastSquaresStatus::converged;
        }
      }
    }

    // J by forward differences at the centre, each step towards the box's interior; one
    // request. False where a difference is not finite.
    bool differentiate() {
      place_stencil(center, stencil);
      objective(stencil, stencil_deviations);
      ++result.batches;
      result.evaluations += dimension();
      keep_best(stencil, stencil_deviations);
      return take_jacobian(stencil_deviations);
    }

    // The forward-difference points at `point` into `points` (d × d): each locator moved by
    // difference_step of the box towards its interior (the signed differences into `steps`).
    void place_stencil(const VectorX& point, Eigen::Ref<MatrixX> points) {
      steps = options.difference_step * width;
      for (Index i = 0; i < d; ++i) {
        if (point(i) + steps(i) > upper(i)) steps(i) = -steps(i);
        points.col(i) = point;
        points(i, i) += steps(i);
      }
    }

    // J at the centre from its stencil's deviations (`residual` the centre's), and Marquardt's
    // scale diag(JᵀJ). False where a difference is not finite.
    bool take_jacobian(const Eigen::Ref<const MatrixX>& deviations) {
      ++result.jacobians;
      for (Index i = 0; i < d; ++i) {
        jacobian.col(i) = (deviations.col(i) - residual) / steps(i);
      }
      if (!jacobian.allFinite()) return false;
      scale = jacobian.colwise().squaredNorm().transpose();
      scale = scale.cwiseMax(1e-12 * std::max(scale.maxCoeff(), 1e-300));
      return true;
    }
  };

  LeastSquaresSearchOptions options_;
};

}  // namespace twincal
