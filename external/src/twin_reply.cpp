#include "twincal/external/twin_reply.hpp"

#include <cmath>
#include <cstddef>
#include <limits>
#include <utility>
#include <variant>

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

namespace {

TwinReplyFault malformed(std::string_view why, std::string_view line) {
  return TwinReplyFault{ExternalTwinFailure::malformed_reply,
                        fmt::format("{}: {}", why, quoted_output(line))};
}

// The reply's JSON object, once its nesting, syntax, id and the absence of an {"error": …} are
// checked: what every reply shares.
std::variant<nlohmann::json, TwinReplyFault> open_reply(std::string_view line, std::uint64_t id) {
  if (json_nesting_depth(line) > max_json_nesting) {
    return malformed("the reply nests deeper than 64 arrays and objects", line);
  }
  // Without exceptions: invalid UTF-8 and numbers beyond double's range (1e309) are discarded.
  nlohmann::json reply = nlohmann::json::parse(line, nullptr, /*allow_exceptions=*/false);
  if (reply.is_discarded()) return malformed("the reply is not JSON", line);
  if (!reply.is_object()) return malformed("the reply is not a JSON object", line);
  if (const auto echoed = reply.find("id"); echoed != reply.end() && *echoed != id) {
    return malformed(fmt::format("the reply is for request {}, not {}", quoted(*echoed), id), line);
  }
  if (const auto error = reply.find("error"); error != reply.end()) {
    // The twin's own words (valid UTF-8: the parser refuses anything else); any other value,
    // and an empty message, as JSON text, so the detail never reads as nothing.
    const bool words = error->is_string() && !error->get_ref<const std::string&>().empty();
    return TwinReplyFault{ExternalTwinFailure::twin_error,
                          words ? error->get<std::string>() : quoted(*error)};
  }
  return reply;
}

// The reply's "qualities" array (found: it is one) into `qualities`.
std::optional<TwinReplyFault> read_qualities(const nlohmann::json& found, std::string_view line,
                                             double max_quality, Eigen::Ref<VectorX> qualities) {
  if (static_cast<Index>(found.size()) != qualities.size()) {
    return TwinReplyFault{ExternalTwinFailure::wrong_count,
                          fmt::format("the reply has {} qualities; rule: must have {}, one per "
                                      "control",
                                      found.size(), qualities.size())};
  }
  for (Index j = 0; j < qualities.size(); ++j) {
    const nlohmann::json& q = found[static_cast<std::size_t>(j)];
    if (q.is_null()) {
      qualities(j) = std::numeric_limits<double>::quiet_NaN();
      continue;
    }
    if (!q.is_number())
      return malformed(fmt::format("quality {} is not a number or null", j), line);
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

// Control j's entry of a "deviations" array into column j of `deviations` (m rows): m numbers
// in ±max_quality, or null for a NaN column.
std::optional<TwinReplyFault> read_deviation_column(const nlohmann::json& column, Index j,
                                                    std::string_view line, double max_quality,
                                                    Eigen::Ref<MatrixX> deviations) {
  const Index m = deviations.rows();
  if (column.is_null()) {
    deviations.col(j).setConstant(std::numeric_limits<double>::quiet_NaN());
    return std::nullopt;
  }
  if (!column.is_array()) {
    return malformed(fmt::format("the deviations of control {} are not an array or null", j), line);
  }
  if (static_cast<Index>(column.size()) != m) {
    return TwinReplyFault{ExternalTwinFailure::wrong_count,
                          fmt::format("control {} has {} deviations; rule: must have {}, one per "
                                      "key point (key_points)",
                                      j, column.size(), m)};
  }
  for (Index i = 0; i < m; ++i) {
    const nlohmann::json& r = column[static_cast<std::size_t>(i)];
    if (!r.is_number()) {
      return malformed(fmt::format("deviation {} of control {} is not a number", i, j), line);
    }
    deviations(i, j) = r.get<double>();
    if (!(std::abs(deviations(i, j)) <= max_quality)) {
      return TwinReplyFault{ExternalTwinFailure::implausible_quality,
                            fmt::format("deviation {} of control {} is {}; rule: a deviation lies "
                                        "in [-max_quality, max_quality] = ±{} mm",
                                        i, j, quoted(r), max_quality)};
    }
  }
  return std::nullopt;
}

// The qualities a reply states beside its deviations: each the RMS of its column, to a relative
// 1e-6, null where the column is.
std::optional<TwinReplyFault> check_stated_qualities(const nlohmann::json& stated,
                                                     std::string_view line, double max_quality,
                                                     const Eigen::Ref<const MatrixX>& deviations) {
  if (!stated.is_array()) return malformed("the reply's \"qualities\" is not an array", line);
  VectorX qualities(deviations.cols());
  if (auto fault = read_qualities(stated, line, max_quality, qualities)) return fault;
  for (Index j = 0; j < deviations.cols(); ++j) {
    const double rms = deviations.col(j).norm() / std::sqrt(static_cast<double>(deviations.rows()));
    const bool agree = std::isnan(rms) ? std::isnan(qualities(j))
                                       : std::abs(qualities(j) - rms) <= 1e-6 * rms + 1e-12;
    if (!agree) {
      return TwinReplyFault{
          ExternalTwinFailure::implausible_quality,
          fmt::format("quality {} is {} but {}; rule: a quality sent with deviations is their RMS "
                      "to a relative 1e-6, null for null deviations",
                      j, std::isnan(qualities(j)) ? "null" : fmt::format("{}", qualities(j)),
                      std::isnan(rms) ? "its deviations are null"
                                      : fmt::format("its deviations' RMS is {}", rms))};
    }
  }
  return std::nullopt;
}

}  // namespace

std::optional<TwinReplyFault> read_twin_reply(std::string_view line, std::uint64_t id,
                                              double max_quality, Eigen::Ref<VectorX> qualities) {
  std::variant<nlohmann::json, TwinReplyFault> opened = open_reply(line, id);
  if (auto* fault = std::get_if<TwinReplyFault>(&opened)) return std::move(*fault);
  const nlohmann::json& reply = std::get<nlohmann::json>(opened);
  const auto found = reply.find("qualities");
  if (found == reply.end() || !found->is_array()) {
    return malformed("the reply has no \"qualities\" array", line);
  }
  return read_qualities(*found, line, max_quality, qualities);
}

std::optional<TwinReplyFault> read_twin_deviations_reply(std::string_view line, std::uint64_t id,
                                                         double max_quality,
                                                         Eigen::Ref<MatrixX> deviations) {
  std::variant<nlohmann::json, TwinReplyFault> opened = open_reply(line, id);
  if (auto* fault = std::get_if<TwinReplyFault>(&opened)) return std::move(*fault);
  const nlohmann::json& reply = std::get<nlohmann::json>(opened);
  const auto found = reply.find("deviations");
  if (found == reply.end() || !found->is_array()) {
    return malformed("the reply has no \"deviations\" array (the request asked for them)", line);
  }
  if (static_cast<Index>(found->size()) != deviations.cols()) {
    return TwinReplyFault{ExternalTwinFailure::wrong_count,
                          fmt::format("the reply has {} arrays of deviations; rule: must have {}, "
                                      "one per control",
                                      found->size(), deviations.cols())};
  }
  for (Index j = 0; j < deviations.cols(); ++j) {
    if (auto fault = read_deviation_column((*found)[static_cast<std::size_t>(j)], j, line,
                                           max_quality, deviations)) {
      return fault;
    }
  }
  const auto stated = reply.find("qualities");
  if (stated == reply.end()) return std::nullopt;
  return check_stated_qualities(*stated, line, max_quality, deviations);
}

}  // namespace twincal
