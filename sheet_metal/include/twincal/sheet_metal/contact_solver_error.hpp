#pragma once
/// @file
/// `ContactSolverError`: the contact problem (contact_solver.hpp) could not be solved. It carries
/// the solver's summary (status, solves spent, residual), so a caller can log how far the solver
/// got; the message names the quantity at fault, the value and the rule, like every twincal
/// error. The status and the summary live here, with the error that carries them, so that the
/// solver's header and this one do not include each other.

#include <string>
#include <string_view>
#include <utility>

#include "twincal/core/eigen.hpp"
#include "twincal/core/error.hpp"

namespace twincal {

/// How a contact solve ended.
enum class ContactSolverStatus {
  solved,           ///< the complementarity conditions hold (see ContactSolver's stopping rule)
  iteration_limit,  ///< max_iterations subproblem solves were not enough
  singular,         ///< the compliance of the closed contacts is singular: no solution exists
                    ///< (a pair that cannot move is pressed into penetration) or round-off
                    ///< made a dependent contact look necessary
};

[[nodiscard]] constexpr std::string_view to_string(ContactSolverStatus status) noexcept {
  switch (status) {
    case ContactSolverStatus::solved:
      return "solved";
    case ContactSolverStatus::iteration_limit:
      return "iteration_limit";
    case ContactSolverStatus::singular:
      return "singular";
  }
  return "unknown";
}

/// What a contact solve did.
struct ContactSolverSummary {
  ContactSolverStatus status = ContactSolverStatus::solved;
  Index iterations = 0;  ///< subproblem solves (active-set changes); 0 when every gap is open
  Index closed = 0;      ///< contacts carrying a force (f_k > 0) at the end
  /// The natural residual max_k |min(C_kk f_k, g_k)| (mm): 0 exactly at an LCP solution, since
  /// it is 0 iff f ≥ 0, g ≥ 0 and f_k g_k = 0 for every k (f scaled by C_kk to a length).
  double residual = 0.0;
  /// |fᵀg| (N mm): the complementarity product, round-off at a solution.
  double complementarity = 0.0;
};

class ContactSolverError : public Error {
 public:
  ContactSolverError(std::string argument, const std::string& message, ContactSolverSummary summary)
      : Error(std::move(argument), message), summary_(summary) {}

  /// Where the solver stopped (status other than solved).
  [[nodiscard]] const ContactSolverSummary& summary() const noexcept { return summary_; }

 private:
  ContactSolverSummary summary_;
};

}  // namespace twincal
