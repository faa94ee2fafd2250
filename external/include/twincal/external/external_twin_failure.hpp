#pragma once
/// @file
/// `ExternalTwinFailure`: what went wrong with an external twin (docs/external.md lists what
/// twincal does after each).

#include <string_view>

namespace twincal {

/// What went wrong with an external twin.
enum class ExternalTwinFailure {
  start_failed,         ///< the executable could not be started
  crashed,              ///< the child exited or closed its output during a request
  timeout,              ///< no reply before the deadline (the child was killed)
  malformed_reply,      ///< the reply was not the protocol's JSON (the child was killed)
  wrong_count,          ///< the reply had a different number of qualities (or deviations) than
                        ///< controls (or key points)
  twin_error,           ///< the child answered {"error": …}
  implausible_quality,  ///< a quality below 0 or above max_quality, a deviation beyond
                        ///< ±max_quality, or qualities that are not their deviations' RMS (the
                        ///< child is kept)
};

[[nodiscard]] constexpr std::string_view to_string(ExternalTwinFailure failure) noexcept {
  switch (failure) {
    case ExternalTwinFailure::start_failed:
      return "could not start";
    case ExternalTwinFailure::crashed:
      return "crashed";
    case ExternalTwinFailure::timeout:
      return "timed out";
    case ExternalTwinFailure::malformed_reply:
      return "malformed reply";
    case ExternalTwinFailure::wrong_count:
      return "wrong number of qualities or deviations";
    case ExternalTwinFailure::twin_error:
      return "reported an error";
    case ExternalTwinFailure::implausible_quality:
      return "answered an implausible quality or deviation";
  }
  return "unknown failure";
}

}  // namespace twincal
