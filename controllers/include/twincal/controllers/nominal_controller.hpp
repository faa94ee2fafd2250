#pragma once
/// @file
/// `NominalController`: Def. 1, eq. (2). One control u⁰ = argmin_u Q(x⁰, u; θ0), optimal for a
/// reference assembly x⁰, applied to every assembly. It does not learn from measurements.

#include <string_view>
#include <utility>

#include <nlohmann/json.hpp>

#include "twincal/controllers/controller_state_json.hpp"
#include "twincal/controllers/individual_optimum.hpp"
#include "twincal/controllers/nlopt_optimizer.hpp"
#include "twincal/controllers/optimizer.hpp"
#include "twincal/core/eigen.hpp"
#include "twincal/models/twin.hpp"

namespace twincal {

template <Twin T, Optimizer O = NloptOptimizer>
class NominalController {
 public:
  using Assembly = typename T::Assembly;
  using ControlVector = VectorX;

  /// Computes u⁰ for the reference assembly x⁰ once.
  NominalController(const T& twin, const Assembly& reference, O optimizer = O{})
      : nominal_(IndividualOptimum<T, O>(twin, std::move(optimizer))(reference)) {}

  /// u⁰, whatever the assembly.
  [[nodiscard]] const ControlVector& propose(const Assembly& /*assembly*/) const noexcept {
    return nominal_.control;
  }

  /// The nominal controller ignores feedback.
  void observe(const Assembly& /*assembly*/, const ControlVector& /*control*/,
               double /*z*/) const noexcept {}

  /// u⁰, Q(x⁰, u⁰) and the evaluations spent finding them.
  [[nodiscard]] const IndividualControl& nominal() const noexcept { return nominal_; }

  static constexpr std::string_view json_format = "twincal.nominal_controller";

  /// The snapshot of a controller that learns nothing: its format and dimension (u⁰ is the
  /// constructor's, from the same twin and reference assembly).
  [[nodiscard]] nlohmann::json save() const {
    return {{"format", json_format}, {"dimension", nominal_.control.size()}};
  }

  /// Checks a snapshot of save(). @throws InvalidArgumentError, DimensionMismatchError.
  void restore(const nlohmann::json& saved) const {
    json_state::require_header(saved, json_format, nominal_.control.size());
  }

 private:
  IndividualControl nominal_;
};

}  // namespace twincal
