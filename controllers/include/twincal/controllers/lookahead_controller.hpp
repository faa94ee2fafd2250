#pragma once
/// @file
/// `LookaheadController<Filter, Sampler, Exploit, Explore>`: the paper's w-controller,
/// eqs. (11)–(14). Per assembly x_t:
///   1. u0 = u0(x_t) (eq. 3) and the filter's predict: δû, P (eq. 8);
///   2. candidates: the sampler's points mapped to N(û*, P), û* = u0 + δû (eq. 9), those outside
///      U_t = {|u − û*|_∞ <= h} disregarded (eq. 14);
///   3. ONE twin batch: Q(x_t, u_c − s_i) for every candidate u_c and sigma point s_i;
///   4. per candidate: exploit = Σ W_i Q(x_t, u_c − s_i) (eq. 11), the filter's preview of P⁺(u_c)
///      from the same values, explore = loss(P⁺) (eq. 12), L_w (eq. 13); the argmin is u_t;
///   5. observe(x_t, u_t, z_t) commits the chosen candidate's preview with z_t: the update
///      evaluates nothing. Q-evaluations per assembly = candidates × sigma points.
/// The policies — filter (UKF, CKF, square-root, …), sampler (Sobol, Halton, …), losses — are
/// members, so an ablation is a type change.
///
/// Failure policy: if drawing, evaluating or previewing fails (a twin error, a non-finite value,
/// a posterior that cannot be factored), u_t is the default control û*, the reason is recorded in
/// last_proposal().fallback, and the filter (already predicted, as every controller's is) is not
/// touched; observe then runs an ordinary update, and drops z_t if the twin fails there too
/// (update_or_drop). When no candidate survives the box, the default
/// control, the box's centre, is the only candidate.

#include <algorithm>
#include <array>
#include <cstddef>
#include <exception>
#include <limits>
#include <string_view>
#include <type_traits>
#include <utility>

#include <fmt/format.h>
#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "twincal/controllers/controller.hpp"
#include "twincal/controllers/controller_state_json.hpp"
#include "twincal/controllers/expected_quality.hpp"
#include "twincal/controllers/exploitation_loss.hpp"
#include "twincal/controllers/exploration_loss.hpp"
#include "twincal/controllers/individual_optimum.hpp"
#include "twincal/controllers/lookahead_options.hpp"
#include "twincal/controllers/nlopt_optimizer.hpp"
#include "twincal/controllers/optimizer.hpp"
#include "twincal/controllers/proposal_report.hpp"
#include "twincal/controllers/quality_filter.hpp"
#include "twincal/controllers/sampler_state.hpp"
#include "twincal/controllers/trace_loss.hpp"
#include "twincal/controllers/update_or_drop.hpp"
#include "twincal/core/eigen.hpp"
#include "twincal/core/options.hpp"
#include "twincal/core/validate.hpp"
#include "twincal/samplers/box_set.hpp"
#include "twincal/samplers/candidates.hpp"
#include "twincal/samplers/gaussian_transform.hpp"
#include "twincal/samplers/sampler.hpp"

namespace twincal {

template <QualityFilter F, Sampler S, ExploitationLoss Exploit = ExpectedQuality,
          typename Explore = TraceLoss, Optimizer O = NloptOptimizer>
requires ExplorationLoss<Explore, F::dimension_at_compile_time>
class LookaheadController {
 public:
  static constexpr int dimension_at_compile_time = F::dimension_at_compile_time;
  using Filter = F;
  using Twin = std::remove_cvref_t<decltype(std::declval<const F&>().measurement_model().twin())>;
  using Assembly = typename MeasurementModelOf<F>::Assembly;
  using ControlVector = typename F::StateVector;
  using Preview = typename F::Preview;

  /// @throws InvalidArgumentError (options), DimensionMismatchError (the sampler's dimension is
  ///         not the filter's; the filter has already checked its own against the twin).
  LookaheadController(F filter, S sampler, LookaheadOptions options = {}, Exploit exploit = {},
                      Explore explore = {}, O optimizer = O{})
      : filter_(std::move(filter)),
        sampler_(std::move(sampler)),
        options_(std::move(options)),
        exploit_(std::move(exploit)),
        explore_(std::move(explore)),
        optimum_(filter_.measurement_model().twin(), std::move(optimizer)) {
    require_valid("LookaheadOptions", options_);
    const Index d = filter_.dimension();
    require_dimension("sampler.dimension()", static_cast<Index>(sampler_.dimension()), d);
    qualities_.resize(filter_.sigma_points().cols(), options_.candidate_count(d));
  }

  /// Chooses u_t for assembly x_t (steps 1–4 of the file comment).
  [[nodiscard]] ControlVector propose(const Assembly& assembly) {
    const IndividualControl u0 = optimum_(assembly);
    filter_.predict();
    has_pending_ = false;
    report_.reset();
    report_.individual_control = u0.control;
    report_.optimal_quality = u0.quality;
    report_.optimizer_evaluations = u0.evaluations;
    const ControlVector center = u0.control + filter_.state();
    report_.default_control = center;
    try {
      choose(assembly, center);
    } catch (const std::exception& error) {
      has_pending_ = false;
      report_.chosen = -1;
      report_.control = center;
      report_.fallback = error.what();
      return center;
    }
    return chosen_;
  }

  /// Updates the filter with z_t: commits the chosen candidate's preview when `control` is the
  /// proposal (no evaluation), otherwise an ordinary update at `control`, which drops z_t when
  /// the twin fails at its sigma points (update_or_drop: last_proposal() says why).
  void observe(const Assembly& assembly, const ControlVector& control, double z) {
    require_dimension("control", control.size(), filter_.dimension());
    if (has_pending_ && control == chosen_) {
      filter_.commit(previews_[pending_slot_], z);
    } else {
      update_or_drop(filter_, z, {assembly, control}, report_);
    }
    has_pending_ = false;
  }

  /// Drops the proposal's preview, so the next observe evaluates the measurement afresh: for
  /// owners that change the measurement's context between propose and observe
  /// (PerComponentController).
  void forget_proposal() noexcept { has_pending_ = false; }

  [[nodiscard]] const ControlVector& offset_estimate() const noexcept { return filter_.state(); }
  [[nodiscard]] MatrixX offset_covariance() const { return filter_.covariance(); }
  [[nodiscard]] const F& filter() const noexcept { return filter_; }
  [[nodiscard]] const S& sampler() const noexcept { return sampler_; }
  [[nodiscard]] const LookaheadOptions& options() const noexcept { return options_; }
  [[nodiscard]] const ProposalReport& last_proposal() const noexcept { return report_; }

  static constexpr std::string_view json_format = "twincal.lookahead_controller";

  /// The filter's state (its own save()), the sampler's position (sampler_state.hpp), the last
  /// proposal's report and, between propose and observe, the pending proposal u_t with the
  /// preview observe commits (eq. 12's P⁺(u_t)). The losses, options and u0 are settings.
  [[nodiscard]] nlohmann::json save() const requires SnapshotFilter<F> && SnapshotSampler<S> {
    nlohmann::json saved{{"format", json_format},
                         {"dimension", filter_.dimension()},
                         {"filter", filter_.save()},
                         {"sampler", save_sampler(sampler_)},
                         {"report", json_state::report_to_json(report_)},
                         {"pending", has_pending_}};
    if (has_pending_) {
      saved["pending_slot"] = pending_slot_;
      saved["chosen"] = json_state::doubles_to_json(chosen_);
      saved["preview"] = json_state::preview_to_json(previews_[pending_slot_]);
    }
    return saved;
  }

  /// Restores a snapshot of save() into a controller built like the saved one (same filter
  /// settings, sampler kind and options).
  /// @throws InvalidArgumentError, DimensionMismatchError, NonFiniteError,
  ///         NotPositiveDefiniteError naming the field ("filter.covariance", "sampler.seed");
  ///         the controller unchanged.
  void restore(const nlohmann::json& saved) requires SnapshotFilter<F> && SnapshotSampler<S> {
    const Index d = filter_.dimension();
    json_state::require_header(saved, json_format, d);
    const nlohmann::json& saved_filter = json_state::field(saved, "filter");
    const nlohmann::json& saved_sampler = json_state::field(saved, "sampler");
    const nlohmann::json& saved_report = json_state::field(saved, "report");
    ProposalReport report =
        json_state::within("report", [&] { return json_state::read_report(saved_report, d); });
    const bool pending = json_state::read_bool(saved, "pending");
    std::size_t slot = pending_slot_;
    ControlVector chosen = ControlVector::Zero(d);
    Preview preview;
    if (pending) {
      slot = static_cast<std::size_t>(json_state::read_integer_field(saved, "pending_slot", 0, 1));
      chosen =
          json_state::read_vector<ControlVector>(json_state::field(saved, "chosen"), "chosen", d);
      const nlohmann::json& saved_preview = json_state::field(saved, "preview");
      preview = json_state::within(
          "preview", [&] { return json_state::read_preview<Preview>(saved_preview, d); });
    }
    S sampler = sampler_;
    json_state::within("sampler", [&] { restore_sampler(sampler, saved_sampler); });
    // The filter last: its restore is all or nothing, and nothing throws after it.
    json_state::within("filter", [&] { filter_.restore(saved_filter); });
    sampler_ = std::move(sampler);
    report_ = std::move(report);
    has_pending_ = pending;
    if (pending) {
      pending_slot_ = slot;
      chosen_ = std::move(chosen);
      preview.revision = filter_.revision();  // the preview of the restored state
      previews_[slot] = std::move(preview);
    }
  }

 private:
  void choose(const Assembly& assembly, const ControlVector& center) {
    const Index d = center.size();
    const Index count = options_.candidate_count(d);
    const GaussianTransform<dimension_at_compile_time> transform(center, filter_.covariance(),
                                                                 options_.transform);
    const BoxSet<dimension_at_compile_time> box =
        BoxSet<dimension_at_compile_time>::cube(center, options_.box_half_width);
    candidates_.draw(sampler_, transform, box,
                     {.count = count,
                      .keep_drawing = options_.keep_drawing,
                      .max_batches = options_.max_batches});
    report_.candidates_requested = count;
    report_.candidates_drawn = candidates_.drawn();
    report_.candidates_survived = candidates_.survived();
    if (candidates_.size() > 0) {
      score(assembly, candidates_.points());
    } else {
      centre_ = center;  // nothing survived U_t: score the box's centre
      score(assembly, centre_);
    }
  }

  // Scores the d × C `candidates` (one twin batch for all of them) and keeps the best.
  void score(const Assembly& assembly, const Eigen::Ref<const MatrixX>& candidates) {
    const Index scored = candidates.cols();
    const Index m = filter_.sigma_points().cols();
    report_.candidates_scored = scored;
    Eigen::Block<MatrixX, Dynamic, Dynamic, true> qualities = qualities_.leftCols(scored);
    filter_.measurement_model().measure_grid(assembly, candidates, filter_.sigma_points(),
                                             qualities);
    report_.quality_evaluations = static_cast<std::uint64_t>(scored * m);

    double best = std::numeric_limits<double>::infinity();
    for (Index c = 0; c < scored; ++c) {
      const double exploitation = exploit_(qualities.col(c), filter_.mean_weights());
      // Into the kept preview that is not the best so far, where the filter offers that form:
      // no allocation per candidate at Dynamic sizes, and a new best is a change of slot.
      Preview& scratch = previews_[1 - pending_slot_];
      if constexpr (requires { filter_.preview(qualities.col(c), scratch); }) {
        filter_.preview(qualities.col(c), scratch);
      } else {
        scratch = filter_.preview(qualities.col(c));
      }
      const double exploration = explore_(scratch.posterior_covariance);
      const double loss = (1.0 - options_.w) * exploitation + options_.w * exploration;
      require_finite(fmt::format("L_w of candidate {}", c), loss);
      if (loss < best) {  // ties keep the first: the sampler's order decides
        best = loss;
        pending_slot_ = 1 - pending_slot_;
        has_pending_ = true;
        report_.chosen = c;
        report_.exploitation = exploitation;
        report_.exploration = exploration;
        report_.loss = loss;
      }
    }
    chosen_ = candidates.col(report_.chosen);
    report_.control = chosen_;
  }

  F filter_;
  S sampler_;
  LookaheadOptions options_;
  Exploit exploit_;
  Explore explore_;
  IndividualOptimum<Twin, O> optimum_;
  // Workspaces sized once for the candidate budget, so propose does not allocate for them.
  CandidateSet<dimension_at_compile_time> candidates_;
  MatrixX qualities_;
  ControlVector centre_;
  ControlVector chosen_;
  // The chosen candidate's preview (previews_[pending_slot_], committed by observe when
  // has_pending_) and the one being scored.
  std::array<Preview, 2> previews_;
  std::size_t pending_slot_ = 0;
  bool has_pending_ = false;
  ProposalReport report_;
};

}  // namespace twincal
