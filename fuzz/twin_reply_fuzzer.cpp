// Any bytes as an external twin's reply line (docs/external.md): read_twin_reply and
// read_twin_deviations_reply answer the qualities (the deviations) or a fault, never an
// exception, and what they read obeys the protocol's rules.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <optional>
#include <string_view>

#include <fmt/format.h>

#include "twincal/external/twin_reply.hpp"

namespace {

constexpr double max_quality = 1e6;

[[noreturn]] void broken(std::string_view rule) {
  fmt::print(stderr, "twin_reply fuzzer: {}\n", rule);
  std::abort();
}

// A fault names a reply's failure and says what is wrong.
void check_fault(const twincal::TwinReplyFault& fault) {
  using twincal::ExternalTwinFailure;
  if (fault.detail.empty()) broken("a fault without a detail");
  switch (fault.failure) {
    case ExternalTwinFailure::malformed_reply:
    case ExternalTwinFailure::wrong_count:
    case ExternalTwinFailure::twin_error:
    case ExternalTwinFailure::implausible_quality:
      return;
    default:
      broken(fmt::format("a reply cannot be '{}'", to_string(fault.failure)));
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace twincal;
  const std::string_view line(reinterpret_cast<const char*>(data), size);
  // Two controls per request, as in the seeds: a mutation that adds or drops one is a wrong count.
  VectorX qualities(2);
  if (const std::optional<TwinReplyFault> fault =
          read_twin_reply(line, 7, max_quality, qualities)) {
    check_fault(*fault);
  } else {
    for (Index j = 0; j < qualities.size(); ++j) {
      if (!std::isnan(qualities(j)) && !(qualities(j) >= 0.0 && qualities(j) <= max_quality)) {
        broken(fmt::format("read quality {} = {} outside [0, {}]", j, qualities(j), max_quality));
      }
    }
  }
  // The same bytes as the deviations of 2 key points of those 2 controls.
  MatrixX deviations(2, 2);
  if (const std::optional<TwinReplyFault> fault =
          read_twin_deviations_reply(line, 7, max_quality, deviations)) {
    check_fault(*fault);
    return 0;
  }
  for (Index j = 0; j < deviations.cols(); ++j) {
    const bool unevaluated = deviations.col(j).array().isNaN().all();
    if (!unevaluated && !(deviations.col(j).cwiseAbs().maxCoeff() <= max_quality)) {
      broken(
          fmt::format("read deviations of control {} beyond ±{} (or partly NaN)", j, max_quality));
    }
  }
  return 0;
}
