#pragma once
/// @file
/// `DefaultController<Filter>`: eq. (9), u_t = u0(x_t) + δû_t — the individualized control
/// corrected by the filter's current offset estimate, with no deliberate exploration. It may
/// lose track of the offset when the measurements stop exciting the filter (Sec. 2.3.2).

#include <string_view>
#include <utility>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "twincal/controllers/controller.hpp"
#include "twincal/controllers/controller_state_json.hpp"
#include "twincal/controllers/individual_optimum.hpp"
#include "twincal/controllers/nlopt_optimizer.hpp"
#include "twincal/controllers/optimizer.hpp"
#include "twincal/controllers/proposal_report.hpp"
#include "twincal/controllers/quality_filter.hpp"
#include "twincal/controllers/update_or_drop.hpp"
#include "twincal/core/eigen.hpp"
#include "twincal/core/validate.hpp"

namespace twincal {

template <QualityFilter F, Optimizer O = NloptOptimizer>
class DefaultController {
 public:
  using Filter = F;
  using Twin = std::remove_cvref_t<decltype(std::declval<const F&>().measurement_model().twin())>;
  using Assembly = typename MeasurementModelOf<F>::Assembly;
  using ControlVector = typename F::StateVector;

  /// The filter's measurement model refers to the twin; the filter has already checked that
  /// its dimension is the twin's control dimension.
  explicit DefaultController(F filter, O optimizer = O{})
      : filter_(std::move(filter)),
        optimum_(filter_.measurement_model().twin(), std::move(optimizer)) {}

  /// Predicts the offset one assembly ahead, then proposes u0(x_t) + δû_t.
  [[nodiscard]] ControlVector propose(const Assembly& assembly) {
    const IndividualControl u0 = optimum_(assembly);
    filter_.predict();
    ControlVector control = u0.control + filter_.state();
    report_.reset();
    report_.individual_control = u0.control;
    report_.optimal_quality = u0.quality;
    report_.optimizer_evaluations = u0.evaluations;
    report_.default_control = control;
    report_.control = control;
    return control;
  }

  /// Updates the filter with the measured quality z_t of the applied control u_t; drops z_t when
  /// the twin fails at the update's sigma points (update_or_drop: last_proposal() says why).
  void observe(const Assembly& assembly, const ControlVector& control, double z) {
    update_or_drop(filter_, z, {assembly, control}, report_);
  }

  [[nodiscard]] const ControlVector& offset_estimate() const noexcept { return filter_.state(); }
  [[nodiscard]] MatrixX offset_covariance() const { return filter_.covariance(); }
  [[nodiscard]] const F& filter() const noexcept { return filter_; }
  [[nodiscard]] const ProposalReport& last_proposal() const noexcept { return report_; }

  static constexpr std::string_view json_format = "twincal.default_controller";

  /// The filter's state (its own save(): δû, P, sigma points, update count) and the last
  /// proposal's report; nothing else carries over between assemblies (u0 is recomputed).
  [[nodiscard]] nlohmann::json save() const requires SnapshotFilter<F> {
    return {{"format", json_format},
            {"dimension", filter_.dimension()},
            {"filter", filter_.save()},
            {"report", json_state::report_to_json(report_)}};
  }

  /// Restores a snapshot of save() into a controller built like the saved one.
  /// @throws InvalidArgumentError, DimensionMismatchError, NonFiniteError,
  ///         NotPositiveDefiniteError naming the field ("filter.covariance"); the controller
  ///         unchanged.
  void restore(const nlohmann::json& saved) requires SnapshotFilter<F> {
    const Index d = filter_.dimension();
    json_state::require_header(saved, json_format, d);
    const nlohmann::json& saved_filter = json_state::field(saved, "filter");
    const nlohmann::json& saved_report = json_state::field(saved, "report");
    ProposalReport report =
        json_state::within("report", [&] { return json_state::read_report(saved_report, d); });
    // The filter last: its restore is all or nothing, and nothing throws after it.
    json_state::within("filter", [&] { filter_.restore(saved_filter); });
    report_ = std::move(report);
  }

 private:
  F filter_;
  IndividualOptimum<Twin, O> optimum_;
  ProposalReport report_;
};

}  // namespace twincal
