#pragma once
/// @file
/// `AnyController`: a type-erased controller over AssemblyId (controller.hpp), so that the
/// experiments' episode loop, `twincal serve` and the Python bindings drive every controller the
/// experiments build — baseline, nominal, default, the w-controllers over every filter, sampler
/// and loss, per-component, active — through one type, compiled once. Controls and estimates go
/// in and out through Eigen::Ref, so a fixed-size controller (d = 1, 3) keeps its fixed-size
/// arithmetic and a step allocates nothing the wrapped controller does not. Move-only: a
/// controller is state. Every wrapped controller is a SnapshotController: save() and restore()
/// let `twincal serve` resume a session from a snapshot instead of replaying its whole history.

#include <concepts>
#include <limits>
#include <memory>
#include <string_view>
#include <utility>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "twincal/controllers/active/active_step_report.hpp"
#include "twincal/controllers/controller.hpp"
#include "twincal/controllers/proposal_report.hpp"
#include "twincal/core/eigen.hpp"
#include "twincal/models/assembly_id.hpp"

namespace twincal {

class AnyController {
 public:
  using Assembly = AssemblyId;

  /// Wraps `controller` (moved in), which controls `control_dimension` locators.
  template <SnapshotController C>
  requires std::same_as<typename C::Assembly, AssemblyId> AnyController(C controller,
                                                                        Index control_dimension)
      : model_(std::make_unique<Model<C>>(std::move(controller), control_dimension)) {}

  [[nodiscard]] Index control_dimension() const noexcept { return model_->dimension; }
  /// Whether the controller estimates the offset (EstimatingController: δû_t and P_t, eq. 8).
  [[nodiscard]] bool estimates() const noexcept { return model_->estimates(); }

  /// u_t = controller.propose(x_t), into `control` (d entries).
  void propose(const AssemblyId& assembly, Eigen::Ref<VectorX> control) {
    model_->propose(assembly, control);
  }
  /// controller.observe(x_t, u_t, z_t).
  void observe(const AssemblyId& assembly, const Eigen::Ref<const VectorX>& control, double z) {
    model_->observe(assembly, control, z);
  }
  /// δû_t into `out` (d entries); zero for a controller that does not estimate (it assumes a
  /// calibrated twin).
  void offset_estimate(Eigen::Ref<VectorX> out) const { model_->offset_estimate(out); }
  /// P_t into `out` (d × d); NaN for a controller that does not estimate.
  void offset_covariance(Eigen::Ref<MatrixX> out) const { model_->offset_covariance(out); }
  /// tr P_t; NaN for a controller that does not estimate.
  [[nodiscard]] double offset_covariance_trace() const { return model_->covariance_trace(); }

  /// What the controller did for its last assembly beyond its control and estimate, as a flat
  /// JSON object: the active controller's ActiveStepReport (active_step_report_to_json); an
  /// empty object for a controller that reports nothing more. `twincal trace` prints it.
  [[nodiscard]] nlohmann::json step_report() const { return model_->step_report(); }

  /// Why the last proposal fell back to the controller's default control
  /// (ProposalReport::fallback: a twin error, a model that could not be fitted); empty when it
  /// did not, or the controller has no fallback. The view is valid until the next propose.
  [[nodiscard]] std::string_view fallback() const noexcept {
    const ProposalReport* report = model_->last_proposal();
    return report != nullptr ? std::string_view(report->fallback) : std::string_view();
  }
  /// Why the last observe dropped its measurement, the estimate staying as predicted
  /// (ProposalReport::dropped_measurement: the twin failed at the update's sigma points); empty
  /// when it did not. Valid until the next propose.
  [[nodiscard]] std::string_view dropped_measurement() const noexcept {
    const ProposalReport* report = model_->last_proposal();
    return report != nullptr ? std::string_view(report->dropped_measurement) : std::string_view();
  }

  /// The wrapped controller's snapshot (SnapshotController, controllers' controller.hpp): what
  /// it carries from one assembly to the next, as JSON that reads back bit for bit.
  [[nodiscard]] nlohmann::json save() const { return model_->save(); }
  /// Restores a save() of a controller built with the same arguments (e.g. the experiments'
  /// make_episode_controller with the same twin, config, spec and run): from then on it behaves
  /// bit for bit like the saved one. @throws the controller's typed errors (InvalidArgumentError,
  ///         DimensionMismatchError, NonFiniteError, NotPositiveDefiniteError) naming the
  ///         field; the controller unchanged.
  void restore(const nlohmann::json& saved) { model_->restore(saved); }

 private:
  struct Concept {
    explicit Concept(Index d) : dimension(d) {}
    virtual ~Concept() = default;
    [[nodiscard]] virtual bool estimates() const noexcept = 0;
    virtual void propose(const AssemblyId&, Eigen::Ref<VectorX>) = 0;
    virtual void observe(const AssemblyId&, const Eigen::Ref<const VectorX>&, double) = 0;
    virtual void offset_estimate(Eigen::Ref<VectorX>) const = 0;
    virtual void offset_covariance(Eigen::Ref<MatrixX>) const = 0;
    [[nodiscard]] virtual double covariance_trace() const = 0;
    [[nodiscard]] virtual nlohmann::json step_report() const = 0;
    // The wrapped controller's ProposalReport, or nullptr for one that keeps none.
    [[nodiscard]] virtual const ProposalReport* last_proposal() const noexcept = 0;
    [[nodiscard]] virtual nlohmann::json save() const = 0;
    virtual void restore(const nlohmann::json&) = 0;
    Index dimension;
  };

  template <typename C>
  struct Model final : Concept {
    Model(C c, Index d) : Concept(d), controller(std::move(c)), control(d) {}
    [[nodiscard]] bool estimates() const noexcept override { return EstimatingController<C>; }
    void propose(const AssemblyId& assembly, Eigen::Ref<VectorX> out) override {
      out = controller.propose(assembly);
    }
    void observe(const AssemblyId& assembly, const Eigen::Ref<const VectorX>& u,
                 double z) override {
      // Into the controller's own vector type, sized once: no allocation per step, and the
      // look-ahead's "is this my proposal?" test sees the same bits.
      control = u;
      controller.observe(assembly, control, z);
    }
    void offset_estimate(Eigen::Ref<VectorX> out) const override {
      if constexpr (EstimatingController<C>) {
        out = controller.offset_estimate();
      } else {
        out.setZero();
      }
    }
    void offset_covariance(Eigen::Ref<MatrixX> out) const override {
      if constexpr (EstimatingController<C>) {
        out = controller.offset_covariance();
      } else {
        out.setConstant(std::numeric_limits<double>::quiet_NaN());
      }
    }
    [[nodiscard]] double covariance_trace() const override {
      if constexpr (EstimatingController<C>) {
        return controller.offset_covariance().trace();
      } else {
        return std::numeric_limits<double>::quiet_NaN();
      }
    }
    [[nodiscard]] nlohmann::json step_report() const override {
      if constexpr (requires(const C& c) { active_step_report_to_json(c.last_step()); }) {
        return active_step_report_to_json(controller.last_step());
      } else {
        return nlohmann::json::object();
      }
    }
    [[nodiscard]] const ProposalReport* last_proposal() const noexcept override {
      if constexpr (requires(const C& c) {
                      { c.last_proposal() } -> std::convertible_to<const ProposalReport&>;
                    }) {
        return &controller.last_proposal();
      } else {
        return nullptr;
      }
    }
    [[nodiscard]] nlohmann::json save() const override { return controller.save(); }
    void restore(const nlohmann::json& saved) override { controller.restore(saved); }
    C controller;
    typename C::ControlVector control;
  };

  std::unique_ptr<Concept> model_;
};

}  // namespace twincal
