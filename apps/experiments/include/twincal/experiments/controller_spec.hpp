#pragma once
/// @file
/// `ControllerSpec`: which controller an episode runs, in the paper's vocabulary (Sec. 2.4):
/// the baseline (individualized, Def. 2, eq. 3), the nominal controller (Def. 1, eq. 2), the
/// default controller (eq. 9) and the w-controllers (eqs. 11–14) — and, beyond the paper, the
/// per-component w-controllers the paper proposes for many locators (Sec. 4) and the active
/// controller (controllers' active_controller.hpp). Spelled "baseline", "nominal", "default",
/// "w=0.3", "per-component:w=0.3" and "active" in configs, on the command line and in result
/// files.

#include <compare>
#include <string>
#include <string_view>
#include <vector>

namespace twincal {

struct ControllerSpec {
  enum class Kind { baseline, nominal, default_control, lookahead, per_component, active };

  Kind kind = Kind::baseline;
  /// Exploration weight of eq. (13); used by lookahead and per_component only.
  double w = 0.0;

  [[nodiscard]] static ControllerSpec baseline() noexcept { return {Kind::baseline, 0.0}; }
  [[nodiscard]] static ControllerSpec nominal() noexcept { return {Kind::nominal, 0.0}; }
  [[nodiscard]] static ControllerSpec default_controller() noexcept {
    return {Kind::default_control, 0.0};
  }
  [[nodiscard]] static ControllerSpec lookahead(double w) noexcept { return {Kind::lookahead, w}; }
  /// d one-locator w-controllers, one per locator (controllers' per_component_controller.hpp).
  [[nodiscard]] static ControllerSpec per_component(double w) noexcept {
    return {Kind::per_component, w};
  }
  [[nodiscard]] static ControllerSpec active() noexcept { return {Kind::active, 0.0}; }

  /// The paper's 13 (baseline, default and the w-controllers for w = 0, 0.1, …, 1) and, as a
  /// 14th, the active controller.
  [[nodiscard]] static std::vector<ControllerSpec> paper();

  /// "baseline", "nominal", "default", "active", "w=<w>" or "per-component:w=<w>" (shortest
  /// exact form: "w=0.3").
  [[nodiscard]] std::string label() const;

  /// Parses a label (also "w=.30"; surrounding blanks are not allowed).
  /// @throws InvalidArgumentError naming the text and the accepted forms; w outside [0, 1].
  [[nodiscard]] static ControllerSpec parse(std::string_view text);

  /// Whether the controller is weighted by `w` (the w-controllers, per component or not).
  [[nodiscard]] bool uses_w() const noexcept {
    return kind == Kind::lookahead || kind == Kind::per_component;
  }

  /// Whether the controller runs a filter (and so has δû_t, P_t and can diverge).
  [[nodiscard]] bool estimates() const noexcept {
    return kind != Kind::baseline && kind != Kind::nominal;
  }

  friend bool operator==(const ControllerSpec&, const ControllerSpec&) = default;
};

}  // namespace twincal
