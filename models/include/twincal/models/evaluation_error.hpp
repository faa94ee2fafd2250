#pragma once
/// @file
/// `EvaluationError`: a twin evaluation that failed, carrying what was evaluated.
///
/// Failures are first-class: an evaluator never drops or patches a value. A twin that throws, a
/// quality that is NaN or infinite, or a call that exceeds its time limit becomes an
/// EvaluationError naming the failure, the assembly and the controls of the failing call (the
/// column, when the failure is pinned to one control). A twin's own exception is kept as the
/// nested exception (std::throw_with_nested), so `std::rethrow_if_nested` reaches the cause.
/// `TwinEvaluationError<Assembly>` additionally carries the assembly itself, typed.

#include <concepts>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

#include <fmt/format.h>
#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/format.hpp"

namespace twincal {

/// Why an evaluation failed.
enum class EvaluationFailure {
  twin_threw,  ///< the twin threw (the nested exception is its error)
  non_finite,  ///< the twin returned NaN or ±∞
  time_limit,  ///< the call took longer than the evaluator's time limit
};

[[nodiscard]] constexpr std::string_view to_string(EvaluationFailure failure) noexcept {
  switch (failure) {
    case EvaluationFailure::twin_threw:
      return "the twin threw";
    case EvaluationFailure::non_finite:
      return "non-finite quality";
    case EvaluationFailure::time_limit:
      return "time limit exceeded";
  }
  return "unknown failure";
}

/// A human-readable description of an assembly for messages: `dump()` for JSON-like values,
/// fmt formatting when available, otherwise a placeholder.
template <typename Assembly>
[[nodiscard]] std::string describe_assembly(const Assembly& assembly) {
  // dump() first: JSON values convert implicitly to strings, which fmt would try (and throw).
  if constexpr (requires {
                  { assembly.dump() } -> std::convertible_to<std::string>;
                }) {
    return assembly.dump();
  } else if constexpr (fmt::is_formattable<Assembly>::value) {
    return fmt::format("{}", assembly);
  } else {
    return "<assembly without a formatter>";
  }
}

class EvaluationError : public TwinError {
 public:
  /// `controls`: d × k controls of the failing call; `column`: the failing control, if known;
  /// `detail`: what happened (the value, the cause's message, the time).
  EvaluationError(EvaluationFailure failure, std::string assembly, MatrixX controls,
                  std::optional<Index> column, const std::string& detail)
      : TwinError("quality", make_message(failure, assembly, controls, column, detail)),
        failure_(failure),
        assembly_(std::move(assembly)),
        controls_(std::move(controls)),
        column_(column) {}

  [[nodiscard]] EvaluationFailure failure() const noexcept { return failure_; }
  /// Description of the assembly (see describe_assembly).
  [[nodiscard]] const std::string& assembly_description() const noexcept { return assembly_; }
  /// The d × k controls of the failing call.
  [[nodiscard]] const MatrixX& controls() const noexcept { return controls_; }
  /// The column of `controls()` that failed, when the failure is pinned to one control.
  [[nodiscard]] std::optional<Index> column() const noexcept { return column_; }

 private:
  static std::string make_message(EvaluationFailure failure, const std::string& assembly,
                                  const MatrixX& controls, std::optional<Index> column,
                                  const std::string& detail) {
    std::string where;
    if (column) {
      where = fmt::format("control {} (column {} of {})", controls.col(*column), *column,
                          controls.cols());
    } else if (controls.cols() == 1) {
      where = fmt::format("control {}", controls.col(0));
    } else {
      where = fmt::format("{} controls {}", controls.cols(), controls);
    }
    return fmt::format("quality: {} for assembly {}, {}: {}", to_string(failure), assembly, where,
                       detail);
  }

  EvaluationFailure failure_;
  std::string assembly_;
  MatrixX controls_;
  std::optional<Index> column_;
};

/// EvaluationError that also carries the assembly as the twin's own type.
template <typename Assembly>
class TwinEvaluationError : public EvaluationError {
 public:
  TwinEvaluationError(EvaluationFailure failure, Assembly assembly, MatrixX controls,
                      std::optional<Index> column, const std::string& detail)
      : EvaluationError(failure, describe_assembly(assembly), std::move(controls), column, detail),
        assembly_(std::move(assembly)) {}

  [[nodiscard]] const Assembly& assembly() const noexcept { return assembly_; }

 private:
  Assembly assembly_;
};

}  // namespace twincal
