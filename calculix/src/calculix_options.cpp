#include "twincal/calculix/calculix_options.hpp"

#include <cmath>

#include <fmt/format.h>

#include "twincal/calculix/calculix_error.hpp"

namespace twincal {

std::optional<std::string> CalculixOptions::validate() const {
  if (executable.empty()) return "executable: value is empty; rule: must name the solver";
  if (scratch_root.empty()) return "scratch_root: value is empty; rule: must name a directory";
  if (refinement < 1 || refinement > 16) {
    return fmt::format("refinement: value is {}; rule: must lie in [1, 16]", refinement);
  }
  if (auto problem = section.validate()) return "section." + *problem;
  if (!(nominal_gap >= 0.0) || !std::isfinite(nominal_gap)) {
    return fmt::format("nominal_gap: value is {}; rule: must be finite and >= 0 (mm)", nominal_gap);
  }
  if (!(gap_stiffness > 0.0) || !std::isfinite(gap_stiffness)) {
    return fmt::format("gap_stiffness: value is {}; rule: must be finite and > 0 (N/mm)",
                       gap_stiffness);
  }
  if (!(open_gap_force > 0.0) || !std::isfinite(open_gap_force)) {
    return fmt::format("open_gap_force: value is {}; rule: must be finite and > 0 (N)",
                       open_gap_force);
  }
  if (contact && !geometric_nonlinearity) {
    return "contact: value is true with geometric_nonlinearity false; rule: CalculiX solves "
           "gap elements only in a nonlinear (NLGEOM) step";
  }
  if (max_increments < 1) {
    return fmt::format("max_increments: value is {}; rule: must be >= 1", max_increments);
  }
  if (max_iterations < 1) {
    return fmt::format("max_iterations: value is {}; rule: must be >= 1", max_iterations);
  }
  if (max_cutbacks < 1) {
    return fmt::format("max_cutbacks: value is {}; rule: must be >= 1", max_cutbacks);
  }
  if (!(locator_bound > 0.0) || !std::isfinite(locator_bound)) {
    return fmt::format("locator_bound: value is {}; rule: must be finite and > 0 (mm)",
                       locator_bound);
  }
  if (solver_threads < 1) {
    return fmt::format("solver_threads: value is {}; rule: must be >= 1", solver_threads);
  }
  if (timeout.count() <= 0) {
    return fmt::format("timeout: value is {} ms; rule: must be > 0", timeout.count());
  }
  return std::nullopt;
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
