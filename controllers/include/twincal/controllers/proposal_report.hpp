#pragma once
/// @file
/// `ProposalReport`: what a filter-based controller did for one assembly — the individualized
/// control it started from, the default control u0 + δû (eq. 9), the candidate set of eq. (14),
/// the chosen candidate's losses (eqs. 11–13), the Q-evaluations spent, and, when something went
/// wrong, why it fell back to the default control — and, once the assembly is observed, why its
/// measurement could not update the estimate (the twin failed at the update's sigma points).

#include <cstdint>
#include <limits>
#include <string>

#include "twincal/core/eigen.hpp"

namespace twincal {

struct ProposalReport {
  VectorX individual_control;      ///< u0(x_t), eq. (3)
  double optimal_quality = 0.0;    ///< z*(x_t) as the twin or optimizer found it
  VectorX default_control;         ///< û*_t = u0 + δû_t, eq. (9)
  VectorX control;                 ///< u_t, the proposal
  Index candidates_requested = 0;  ///< candidate budget
  Index candidates_drawn = 0;      ///< points taken from the sampler
  Index candidates_survived = 0;   ///< drawn points inside U_t
  Index candidates_scored = 0;     ///< candidates scored (the centre alone if none survived)
  Index chosen = -1;               ///< index of the chosen candidate (−1: default control)
  double exploitation = std::numeric_limits<double>::quiet_NaN();  ///< eq. (11) at u_t
  double exploration = std::numeric_limits<double>::quiet_NaN();   ///< eq. (12) at u_t
  double loss = std::numeric_limits<double>::quiet_NaN();          ///< L_w(u_t), eq. (13)
  std::uint64_t quality_evaluations = 0;    ///< Q calls for scoring (candidates × sigma points)
  std::uint64_t optimizer_evaluations = 0;  ///< Q calls for u0 (0 for an exact optimum)
  std::string fallback;  ///< why the default control was used instead (empty: it was not)
  /// Why observe dropped z_t, the estimate staying as predicted (a TwinError in the update; empty:
  /// z_t was used).
  std::string dropped_measurement;

  [[nodiscard]] bool fell_back() const noexcept { return !fallback.empty(); }
  [[nodiscard]] bool dropped() const noexcept { return !dropped_measurement.empty(); }

  /// Back to a fresh report, keeping the vectors' and the string's storage: a controller resets
  /// its report every assembly, and same-size assignments afterwards then allocate nothing.
  void reset() noexcept {
    const auto invalidate = [](VectorX& v) noexcept {
      v.setConstant(std::numeric_limits<double>::quiet_NaN());
    };
    invalidate(individual_control);
    invalidate(default_control);
    invalidate(control);
    optimal_quality = 0.0;
    candidates_requested = 0;
    candidates_drawn = 0;
    candidates_survived = 0;
    candidates_scored = 0;
    chosen = -1;
    exploitation = std::numeric_limits<double>::quiet_NaN();
    exploration = std::numeric_limits<double>::quiet_NaN();
    loss = std::numeric_limits<double>::quiet_NaN();
    quality_evaluations = 0;
    optimizer_evaluations = 0;
    fallback.clear();
    dropped_measurement.clear();
  }
};

}  // namespace twincal
