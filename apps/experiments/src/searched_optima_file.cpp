// SearchedOptima's file (searched_optima_file.hpp): reading, checking and writing it.
#include "twincal/experiments/searched_optima_file.hpp"

#include <cmath>
#include <fstream>
#include <string>
#include <string_view>
#include <system_error>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "twincal/core/error.hpp"

namespace twincal {

namespace {

constexpr std::string_view format_name = "twincal searched optima 1";

// The file's error: "optima_file <path>: <what>; rule: <rule>".
[[noreturn]] void refuse(const std::filesystem::path& path, std::string_view what,
                         std::string_view rule) {
  throw InvalidArgumentError(
      "optima_file", fmt::format("optima_file {}: {}; rule: {}", path.string(), what, rule));
}

// Member `key` of `object`, which must be a JSON object holding it.
const nlohmann::json& member(const std::filesystem::path& path, const nlohmann::json& object,
                             std::string_view where, const char* key) {
  if (!object.is_object() || !object.contains(key)) {
    refuse(path, fmt::format("{} has no \"{}\"", where, key),
           "a file twincal wrote (searched_optima_file.hpp)");
  }
  return object.at(key);
}

double number(const std::filesystem::path& path, const nlohmann::json& value,
              const std::string& where) {
  if (!value.is_number()) refuse(path, fmt::format("{} is {}", where, value.dump()), "a number");
  return value.get<double>();
}

std::uint64_t count(const std::filesystem::path& path, const nlohmann::json& value,
                    const std::string& where) {
  if (!value.is_number_unsigned()) {
    refuse(path, fmt::format("{} is {}", where, value.dump()), "a count (an integer >= 0)");
  }
  return value.get<std::uint64_t>();
}

// The first field in which `found` and `expected` (JSON objects) differ.
std::string first_difference(const nlohmann::json& found, const nlohmann::json& expected) {
  for (const auto& [key, value] : expected.items()) {
    if (!found.contains(key)) return fmt::format("settings.{} is missing", key);
    if (found.at(key) != value) {
      return fmt::format("settings.{} is {} where the config has {}", key, found.at(key).dump(),
                         value.dump());
    }
  }
  for (const auto& [key, value] : found.items()) {
    if (!expected.contains(key)) return fmt::format("settings.{} is not a setting", key);
  }
  return "settings differ";
}

Index pair_count(const ExternalTwinSettings& settings) {
  return settings.upper_parts * settings.lower_parts;
}

std::filesystem::path temporary_beside(const std::filesystem::path& path) {
  std::filesystem::path temporary = path;
  temporary += ".tmp";
  return temporary;
}

}  // namespace

std::optional<SearchedOptima> read_searched_optima(const std::filesystem::path& path,
                                                   const ExternalTwinSettings& settings) {
  std::error_code error;
  if (!std::filesystem::exists(path, error)) return std::nullopt;
  std::ifstream in(path);
  if (!in) refuse(path, "cannot be opened", "a readable file");
  nlohmann::json file;
  try {
    in >> file;
  } catch (const nlohmann::json::exception& parse_error) {
    refuse(path, fmt::format("is not JSON ({})", parse_error.what()),
           "a file twincal wrote (searched_optima_file.hpp)");
  }
  const nlohmann::json& format = member(path, file, "the file", "format");
  if (format != format_name) {
    refuse(path, fmt::format("format is {}", format.dump()), fmt::format("\"{}\"", format_name));
  }
  const nlohmann::json expected = result_defining_json(settings);
  const nlohmann::json& found = member(path, file, "the file", "settings");
  if (found != expected) {
    refuse(path, first_difference(found, expected),
           "the file serves only the settings that searched it (delete it to search again)");
  }
  const nlohmann::json& search = member(path, file, "the file", "search");
  const nlohmann::json& optima = member(path, file, "the file", "optima");
  if (!optima.is_array()) {
    refuse(path, fmt::format("optima is {}", optima.dump()), "a list of the pairs found");
  }
  const auto d = std::ssize(settings.locators);
  SearchedOptima read(d, pair_count(settings));
  read.evaluations =
      count(path, member(path, search, "search", "evaluations"), "search.evaluations");
  read.requests = count(path, member(path, search, "search", "requests"), "search.requests");
  Index after = -1;  // the last pair read, as a column
  for (std::size_t e = 0; e < optima.size(); ++e) {
    const nlohmann::json& entry = optima[e];
    const std::string where = fmt::format("optima[{}]", e);
    const nlohmann::json& upper_index = member(path, entry, where, "upper");
    const nlohmann::json& lower_index = member(path, entry, where, "lower");
    const bool indices = upper_index.is_number_integer() && lower_index.is_number_integer();
    const Index upper = indices ? upper_index.get<Index>() : -1;
    const Index lower = indices ? lower_index.get<Index>() : -1;
    const Index a = upper * settings.lower_parts + lower;
    if (upper < 0 || upper >= settings.upper_parts || lower < 0 || lower >= settings.lower_parts ||
        a <= after) {
      refuse(path,
             fmt::format("{} is the pair ({}, {})", where, upper_index.dump(), lower_index.dump()),
             fmt::format("pairs of parts within {} × {}, upper-major, each once",
                         settings.upper_parts, settings.lower_parts));
    }
    after = a;
    const nlohmann::json& control = member(path, entry, where, "control");
    if (!control.is_array() || std::ssize(control) != d) {
      refuse(path, fmt::format("{}.control is {}", where, control.dump()),
             fmt::format("one number per locator ({})", d));
    }
    for (Index i = 0; i < d; ++i) {
      const auto k = static_cast<std::size_t>(i);
      const double u = number(path, control[k], fmt::format("{}.control[{}]", where, i));
      if (!(u >= settings.lower_bounds[k] && u <= settings.upper_bounds[k])) {
        refuse(path, fmt::format("{}.control[{}] is {}", where, i, control[k].dump()),
               fmt::format("within the bounds of {}, [{}, {}]", settings.locators[k],
                           settings.lower_bounds[k], settings.upper_bounds[k]));
      }
      read.controls(i, a) = u;
    }
    const nlohmann::json& quality = member(path, entry, where, "quality");
    const double z = number(path, quality, where + ".quality");
    if (!std::isfinite(z) || z < 0.0) {
      refuse(path, fmt::format("{}.quality is {}", where, quality.dump()), "finite and >= 0");
    }
    read.qualities(a) = z;
    read.found[static_cast<std::size_t>(a)] = true;
  }
  return read;
}

void write_searched_optima(const std::filesystem::path& path, const ExternalTwinSettings& settings,
                           const SearchedOptima& optima) {
  const Index pairs = pair_count(settings);
  const auto d = std::ssize(settings.locators);
  if (optima.controls.rows() != d || optima.controls.cols() != pairs ||
      optima.qualities.size() != pairs || std::ssize(optima.found) != pairs) {
    refuse(path,
           fmt::format("the optima are {} × {} controls, {} qualities and {} flags",
                       optima.controls.rows(), optima.controls.cols(), optima.qualities.size(),
                       optima.found.size()),
           fmt::format("{} × {}, {} and {}: one per locator and pair", d, pairs, pairs, pairs));
  }
  nlohmann::json entries = nlohmann::json::array();
  for (Index a = 0; a < pairs; ++a) {
    if (!optima.found[static_cast<std::size_t>(a)]) continue;
    entries.push_back({{"upper", a / settings.lower_parts},
                       {"lower", a % settings.lower_parts},
                       {"control", std::vector<double>(optima.controls.col(a).begin(),
                                                       optima.controls.col(a).end())},
                       {"quality", optima.qualities(a)}});
  }
  const nlohmann::json file = {
      {"format", format_name},
      {"settings", result_defining_json(settings)},
      {"search", {{"evaluations", optima.evaluations}, {"requests", optima.requests}}},
      {"optima", std::move(entries)}};
  const std::filesystem::path temporary = temporary_beside(path);
  {
    std::ofstream out(temporary, std::ios::trunc);
    out << file.dump(1) << '\n';
    if (!out.flush()) refuse(temporary, "cannot be written", "a writable file");
  }
  std::error_code error;
  std::filesystem::rename(temporary, path, error);
  if (error) {
    std::filesystem::remove(temporary, error);
    refuse(path, "cannot replace it", "a writable file");
  }
}

void require_writable_optima_file(const std::filesystem::path& path) {
  const std::filesystem::path temporary = temporary_beside(path);
  {
    std::ofstream probe(temporary, std::ios::app);
    if (!probe) {
      refuse(path, "cannot be created",
             "a path in an existing, writable folder (the search's optima are written there)");
    }
  }
  std::error_code error;
  std::filesystem::remove(temporary, error);
}

}  // namespace twincal
