#include "twincal/external/twin_reply.hpp"

#include <cstddef>
#include <limits>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "twincal/core/json_nesting.hpp"

namespace twincal {

namespace {

// A value of a parsed reply as JSON text; strings may hold bytes that are not UTF-8 (quoted as
// U+FFFD, not thrown).
std::string quoted(const nlohmann::json& value) {
  return value.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace

std::string quoted_output(std::string_view text) {
  return quoted(nlohmann::json(std::string(text.substr(0, 200))));
}

std::optional<TwinReplyFault> read_twin_reply(std::string_view line, std::uint64_t id,
                                              double max_quality, Eigen::Ref<VectorX> qualities) {
  const auto malformed = [&](std::string_view why) {
    return TwinReplyFault{ExternalTwinFailure::malformed_reply,
                          fmt::format("{}: {}", why, quoted_output(line))};
  };
  if (json_nesting_depth(line) > max_json_nesting) {
    return malformed("the reply nests deeper than 64 arrays and objects");
  }
  // Without exceptions: invalid UTF-8 and numbers beyond double's range (1e309) are discarded.
  const nlohmann::json reply = nlohmann::json::parse(line, nullptr, /*allow_exceptions=*/false);
  if (reply.is_discarded()) return malformed("the reply is not JSON");
  if (!reply.is_object()) return malformed("the reply is not a JSON object");
  if (const auto echoed = reply.find("id"); echoed != reply.end() && *echoed != id) {
    return malformed(fmt::format("the reply is for request {}, not {}", quoted(*echoed), id));
  }
  if (const auto error = reply.find("error"); error != reply.end()) {
    // The twin's own words (valid UTF-8: the parser refuses anything else); any other value,
    // and an empty message, as JSON text, so the detail never reads as nothing.
    const bool words = error->is_string() && !error->get_ref<const std::string&>().empty();
    return TwinReplyFault{ExternalTwinFailure::twin_error,
                          words ? error->get<std::string>() : quoted(*error)};
  }
  const auto found = reply.find("qualities");
  if (found == reply.end() || !found->is_array()) {
    return malformed("the reply has no \"qualities\" array");
  }
  if (static_cast<Index>(found->size()) != qualities.size()) {
    return TwinReplyFault{ExternalTwinFailure::wrong_count,
                          fmt::format("the reply has {} qualities; rule: must have {}, one per "
                                      "control",
                                      found->size(), qualities.size())};
  }
  for (Index j = 0; j < qualities.size(); ++j) {
    const nlohmann::json& q = (*found)[static_cast<std::size_t>(j)];
    if (q.is_null()) {
      qualities(j) = std::numeric_limits<double>::quiet_NaN();
      continue;
    }
    if (!q.is_number()) return malformed(fmt::format("quality {} is not a number or null", j));
    qualities(j) = q.get<double>();
    if (!(qualities(j) >= 0.0 && qualities(j) <= max_quality)) {
      return TwinReplyFault{
          ExternalTwinFailure::implausible_quality,
          fmt::format("quality {} is {}; rule: a quality is an RMS deviation in [0, max_quality = "
                      "{}] mm, or null for a control the twin could not evaluate",
                      j, quoted(q), max_quality)};
    }
  }
  return std::nullopt;
}

}  // namespace twincal
