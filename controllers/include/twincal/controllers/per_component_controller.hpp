#pragma once
/// @file
/// `PerComponentController<Twin, Component>`: d independent one-locator controllers combined into
/// one — the simplification the paper proposes to escape the curse of dimensionality (Sec. 4):
/// each locator i has its own one-dimensional filter and controller (any controller over a
/// ComponentTwin, e.g. a one-dimensional w-controller), so the cost per assembly grows linearly
/// in d instead of with 2^(2+d) candidates × (2d+1) sigma points.
///
/// propose(x): u0(x) and z*(x) once for the full twin; each component then proposes u_i with the
///   other locators held at their optimum in the twin's frame (c = u0(x));
/// observe(x, u, z): each component updates with the shared z, its twin frame now holding the
///   other locators where they really were, c_j = u_j − δû_j (estimates from before this
///   assembly), so the filters account for each other's exploration. Every update evaluates
///   afresh (the proposal-time previews assumed a different context).

#include <cstdint>
#include <memory>
#include <string_view>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "twincal/controllers/component_twin.hpp"
#include "twincal/controllers/controller.hpp"
#include "twincal/controllers/controller_state_json.hpp"
#include "twincal/controllers/individual_optimum.hpp"
#include "twincal/controllers/nlopt_optimizer.hpp"
#include "twincal/controllers/optimizer.hpp"
#include "twincal/core/eigen.hpp"
#include "twincal/core/validate.hpp"
#include "twincal/models/twin.hpp"

namespace twincal {

template <Twin T, typename Component, Optimizer O = NloptOptimizer>
requires EstimatingController<Component>
class PerComponentController {
 public:
  using Assembly = typename T::Assembly;
  using ControlVector = VectorX;

  /// `make_component(view, i)` builds locator i's controller over its one-locator view (which
  /// lives as long as this controller). @throws what make_component throws.
  template <typename Factory>
  PerComponentController(const T& twin, Factory&& make_component, O optimizer = O{})
      : context_(std::make_shared<ComponentContext<T>>()), optimum_(twin, std::move(optimizer)) {
    const Index d = twin.control_dimension();
    context_->twin = &twin;
    context_->controls = VectorX::Zero(d);
    context_->optimum = VectorX::Zero(d);
    views_.reserve(static_cast<std::size_t>(d));
    components_.reserve(static_cast<std::size_t>(d));
    for (Index i = 0; i < d; ++i) {
      views_.push_back(std::make_unique<ComponentTwin<T>>(context_, i));
      components_.push_back(make_component(std::as_const(*views_.back()), i));
    }
  }

  [[nodiscard]] Index dimension() const noexcept { return static_cast<Index>(views_.size()); }

  [[nodiscard]] ControlVector propose(const Assembly& assembly) {
    const IndividualControl full = optimum_(assembly);
    context_->assembly = assembly;
    context_->optimum = full.control;
    context_->optimal_quality = full.quality;
    context_->controls = full.control;
    ControlVector u(dimension());
    for (Index i = 0; i < dimension(); ++i) {
      u(i) = components_[static_cast<std::size_t>(i)].propose(assembly)(0);
    }
    return u;
  }

  void observe(const Assembly& assembly, const ControlVector& control, double z) {
    require_dimension("control", control.size(), dimension());
    context_->controls = control - offset_estimate();
    for (Index i = 0; i < dimension(); ++i) {
      Component& component = components_[static_cast<std::size_t>(i)];
      if constexpr (requires { component.forget_proposal(); }) component.forget_proposal();
      component.observe(assembly, Vector<1>::Constant(control(i)), z);
    }
  }

  /// (δû_1, …, δû_d).
  [[nodiscard]] VectorX offset_estimate() const {
    VectorX estimate(dimension());
    for (Index i = 0; i < dimension(); ++i) {
      estimate(i) = components_[static_cast<std::size_t>(i)].offset_estimate()(0);
    }
    return estimate;
  }

  /// diag(P_1, …, P_d): the components are independent by construction.
  [[nodiscard]] MatrixX offset_covariance() const {
    MatrixX covariance = MatrixX::Zero(dimension(), dimension());
    for (Index i = 0; i < dimension(); ++i) {
      covariance(i, i) = components_[static_cast<std::size_t>(i)].offset_covariance()(0, 0);
    }
    return covariance;
  }

  [[nodiscard]] const Component& component(Index i) const {
    return components_.at(static_cast<std::size_t>(i));
  }

  static constexpr std::string_view json_format = "twincal.per_component_controller";

  /// Each component's snapshot, in locator order. The shared context (u0, the other locators'
  /// controls) is rewritten by every propose and observe before it is read: not state.
  [[nodiscard]] nlohmann::json save() const requires SnapshotController<Component> {
    nlohmann::json components = nlohmann::json::array();
    for (const Component& component : components_) components.push_back(component.save());
    return {{"format", json_format}, {"dimension", dimension()}, {"components", components}};
  }

  /// Restores a snapshot of save() into a controller built like the saved one.
  /// @throws as the components' restore, naming the field ("components[1].filter.state");
  ///         the controller unchanged.
  void restore(const nlohmann::json& saved) requires SnapshotController<Component> {
    json_state::require_header(saved, json_format, dimension());
    const nlohmann::json& saved_components = json_state::require_array(
        json_state::field(saved, "components"), "components", dimension());
    std::vector<Component> restored = components_;  // all or nothing
    for (std::size_t i = 0; i < restored.size(); ++i) {
      json_state::within(fmt::format("components[{}]", i),
                         [&] { restored[i].restore(saved_components[i]); });
    }
    components_.swap(restored);
  }

 private:
  std::shared_ptr<ComponentContext<T>> context_;
  IndividualOptimum<T, O> optimum_;
  std::vector<std::unique_ptr<ComponentTwin<T>>> views_;  // stable addresses for the filters
  std::vector<Component> components_;
};

}  // namespace twincal
