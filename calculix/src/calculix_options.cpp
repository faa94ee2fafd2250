#include "twincal/calculix/calculix_options.hpp"

#include <cmath>
#include <utility>

#include <fmt/format.h>

#include "twincal/calculix/calculix_error.hpp"
#include "twincal/core/options.hpp"

namespace twincal {

std::optional<std::string> CalculixOptions::validate() const {
  return first_problem(
      {rule::check(!executable.empty(), "executable", "empty", "must name the solver"),
       rule::check(!scratch_root.empty(), "scratch_root", "empty", "must name a directory"),
       rule::check(refinement >= 1 && refinement <= 16, "refinement", refinement,
                   "must lie in [1, 16]"),
       rule::nested("section", section),
       rule::check(std::isfinite(nominal_gap) && nominal_gap >= 0.0, "nominal_gap", nominal_gap,
                   "must be finite and >= 0 (mm)"),
       rule::check(std::isfinite(gap_stiffness) && gap_stiffness > 0.0, "gap_stiffness",
                   gap_stiffness, "must be finite and > 0 (N/mm)"),
       rule::check(std::isfinite(open_gap_force) && open_gap_force > 0.0, "open_gap_force",
                   open_gap_force, "must be finite and > 0 (N)"),
       rule::check(!contact || geometric_nonlinearity, "contact",
                   "true with geometric_nonlinearity false",
                   "CalculiX solves gap elements only in a nonlinear (NLGEOM) step"),
       rule::at_least("max_increments", max_increments, Index{1}),
       rule::at_least("max_iterations", max_iterations, Index{1}),
       rule::at_least("max_cutbacks", max_cutbacks, Index{1}),
       rule::check(std::isfinite(locator_bound) && locator_bound > 0.0, "locator_bound",
                   locator_bound, "must be finite and > 0 (mm)"),
       rule::at_least("solver_threads", solver_threads, Index{1}),
       rule::check(timeout.count() > 0, "timeout", timeout.count(), "must be > 0 (ms)")});
}

const char* to_string(CalculixFailure failure) noexcept {
  switch (failure) {
    case CalculixFailure::missing_executable:
      return "missing_executable";
    case CalculixFailure::deck_error:
      return "deck_error";
    case CalculixFailure::no_convergence:
      return "no_convergence";
    case CalculixFailure::timeout:
      return "timeout";
    case CalculixFailure::crashed:
      return "crashed";
    case CalculixFailure::unreadable_results:
      return "unreadable_results";
  }
  return "unknown";
}

}  // namespace twincal
