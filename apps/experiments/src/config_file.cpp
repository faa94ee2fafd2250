#include "twincal/experiments/config_file.hpp"

#include <array>
#include <fstream>
#include <set>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "twincal/core/error.hpp"
#include "twincal/core/json_nesting.hpp"

namespace twincal {

nlohmann::json parse_config_text(std::string_view text, std::string_view name) {
  using json = nlohmann::json;
  require_json_nesting(text, name);
  // A key given twice in one object is a mistake, not an override: refused, naming it.
  std::vector<std::set<std::string>> keys;  // per open object
  const json::parser_callback_t no_duplicates = [&](int, json::parse_event_t event, json& parsed) {
    if (event == json::parse_event_t::object_start) {
      keys.emplace_back();
    } else if (event == json::parse_event_t::object_end) {
      keys.pop_back();
    } else if (event == json::parse_event_t::key && !keys.empty()) {
      const std::string key = parsed.get<std::string>();
      if (!keys.back().insert(key).second) {
        throw InvalidArgumentError(
            std::string(name),
            fmt::format("{}: the key \"{}\" appears twice in one object; rule: each key at most "
                        "once",
                        name, key));
      }
    }
    return true;
  };
  try {
    return json::parse(text, no_duplicates);
  } catch (const json::exception& error) {
    throw InvalidArgumentError(std::string(name),
                               fmt::format("{}: is not valid JSON ({})", name, error.what()));
  }
}

nlohmann::json read_config_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw InvalidArgumentError(path.string(), fmt::format("{}: cannot be opened", path.string()));
  // Read in chunks (GCC 12 sees a null dereference in istreambuf_iterator's inlined code).
  std::string text;
  std::array<char, 1 << 16> chunk{};
  while (in.read(chunk.data(), chunk.size()) || in.gcount() > 0) {
    text.append(chunk.data(), static_cast<std::size_t>(in.gcount()));
  }
  if (in.bad())
    throw InvalidArgumentError(path.string(), fmt::format("{}: cannot be read", path.string()));
  return parse_config_text(text, path.string());
}

}  // namespace twincal
