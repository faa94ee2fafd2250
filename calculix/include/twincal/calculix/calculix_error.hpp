#pragma once
/// @file
/// `CalculixError`: a CalculiX run that did not give the twin its answer, with the failure's
/// kind and the tail of the solver's log.

#include <string>
#include <utility>

#include "twincal/core/error.hpp"

namespace twincal {

enum class CalculixFailure {
  missing_executable,  ///< the solver cannot be started (not installed, not executable)
  deck_error,          ///< the solver refused the input deck (an *ERROR before any step ran)
  no_convergence,      ///< a nonlinear step did not converge (too many cutbacks)
  timeout,             ///< killed after CalculixOptions::timeout
  crashed,             ///< ended by a signal or an unexpected exit status
  unreadable_results,  ///< finished, but the results file lacks a requested print
};

[[nodiscard]] const char* to_string(CalculixFailure failure) noexcept;

class CalculixError : public Error {
 public:
  CalculixError(CalculixFailure failure, const std::string& message, std::string log_tail)
      : Error("calculix", message), failure_(failure), log_tail_(std::move(log_tail)) {}

  [[nodiscard]] CalculixFailure failure() const noexcept { return failure_; }
  /// The last lines of the solver's output (its *ERROR lines are there).
  [[nodiscard]] const std::string& log_tail() const noexcept { return log_tail_; }

 private:
  CalculixFailure failure_;
  std::string log_tail_;
};

}  // namespace twincal
