#pragma once
/// @file
/// twincal's error types. Every error names the argument (or quantity) at fault, the offending
/// value and the rule it broke, so a message read in a log is enough to find the cause. Errors
/// are thrown before any state changes (strong exception guarantee) unless documented otherwise.

#include <stdexcept>
#include <string>
#include <utility>

namespace twincal {

/// Base of every error twincal throws; `argument()` names the value at fault.
class Error : public std::runtime_error {
 public:
  Error(std::string argument, const std::string& message)
      : std::runtime_error(message), argument_(std::move(argument)) {}

  /// Name of the argument, option or quantity that broke a rule (e.g. "P", "options.alpha").
  [[nodiscard]] const std::string& argument() const noexcept { return argument_; }

 private:
  std::string argument_;
};

/// A value broke a documented rule (range, sign, option consistency).
class InvalidArgumentError : public Error {
 public:
  using Error::Error;
};

/// Sizes of vectors or matrices do not agree.
class DimensionMismatchError : public InvalidArgumentError {
 public:
  DimensionMismatchError(std::string argument, const std::string& message, long long actual,
                         long long expected)
      : InvalidArgumentError(std::move(argument), message), actual_(actual), expected_(expected) {}

  [[nodiscard]] long long actual() const noexcept { return actual_; }
  [[nodiscard]] long long expected() const noexcept { return expected_; }

 private:
  long long actual_;
  long long expected_;
};

/// A twin could not answer: its solver did not converge, its program died, hung or answered an
/// error, its value was not finite. A failure of the twin at the controls it was asked, not of
/// the caller's input: the controllers go on by their documented failure policies (a proposal on
/// the default control; a measurement the estimate cannot be updated with is dropped), where any
/// other error stops them. ExternalTwinError and EvaluationError are TwinErrors; a twin of one's
/// own throws one (or a class derived from it) for a failure it need not repeat elsewhere.
class TwinError : public Error {
 public:
  using Error::Error;
};

/// A NaN or infinity where only finite numbers are allowed (input, twin output, filter state).
class NonFiniteError : public Error {
 public:
  using Error::Error;
};

/// A matrix that must be symmetric positive (semi-)definite is not. Carries the smallest
/// eigenvalue of its symmetric part, the number that tells how far it is from the rule.
class NotPositiveDefiniteError : public Error {
 public:
  NotPositiveDefiniteError(std::string argument, const std::string& message,
                           double smallest_eigenvalue)
      : Error(std::move(argument), message), smallest_eigenvalue_(smallest_eigenvalue) {}

  [[nodiscard]] double smallest_eigenvalue() const noexcept { return smallest_eigenvalue_; }

 private:
  double smallest_eigenvalue_;
};

}  // namespace twincal
