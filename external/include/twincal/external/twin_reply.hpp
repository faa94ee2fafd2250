#pragma once
/// @file
/// `read_twin_reply` and `read_twin_deviations_reply`: the qualities (or the key points'
/// deviations) of one reply line of the external-twin protocol (docs/external.md), or what is
/// wrong with it. Pure — no process, no I/O — so the parser the twins' bytes reach first is
/// tested and fuzzed on its own (fuzz/twin_reply_fuzzer.cpp).

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "twincal/core/eigen.hpp"
#include "twincal/external/external_twin_failure.hpp"

namespace twincal {

/// What is wrong with a reply: malformed_reply, twin_error, wrong_count or implausible_quality,
/// and a message that quotes the offending part (as JSON text: any bytes can be shown safely).
struct TwinReplyFault {
  ExternalTwinFailure failure;
  std::string detail;
};

/// Reads `line`, the reply to request `id` for `qualities.size()` controls, into `qualities`:
/// numbers in [0, max_quality], NaN for null. The line's nesting is checked before it is parsed
/// (max_json_nesting), and every byte sequence — invalid UTF-8, numbers beyond double's range,
/// any value of any type — is a fault, never an exception. `qualities` is unspecified after a
/// fault.
[[nodiscard]] std::optional<TwinReplyFault> read_twin_reply(std::string_view line, std::uint64_t id,
                                                            double max_quality,
                                                            Eigen::Ref<VectorX> qualities);

/// Reads `line`, the reply to a request `id` that asked for the key points' deviations
/// ("deviations": true), into `deviations` (m × k: one column per control): each control's
/// entry is an array of m numbers in [−max_quality, max_quality] mm, or null for a control the
/// twin could not evaluate (a NaN column). A "qualities" array beside them is optional; when
/// present it must hold RMS(r) of each control to a relative 1e-6 (implausible_quality
/// otherwise), so a twin cannot answer two different truths. Faults as read_twin_reply;
/// `deviations` is unspecified after one.
[[nodiscard]] std::optional<TwinReplyFault> read_twin_deviations_reply(
    std::string_view line, std::uint64_t id, double max_quality, Eigen::Ref<MatrixX> deviations);

/// The first 200 bytes of a child's output as a JSON string: bytes that are not UTF-8 become
/// U+FFFD, so a message can go anywhere text goes (a results file, a serve reply).
[[nodiscard]] std::string quoted_output(std::string_view text);

}  // namespace twincal
