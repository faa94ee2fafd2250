#pragma once
/// @file
/// `NominalController`: Def. 1, eq. (2). One control u⁰ = argmin_u Q(x⁰, u; θ0), optimal for a
/// reference assembly x⁰, applied to every assembly. It does not learn from measurements.

#include <utility>

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

 private:
  IndividualControl nominal_;
};

}  // namespace twincal
