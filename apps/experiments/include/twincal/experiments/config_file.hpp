#pragma once
/// @file
/// `parse_config_text` and `read_config_file`: the JSON document of a config or sweep file
/// (docs/cli.md), read the one way every command reads it — the nesting checked on the raw bytes
/// before the parser runs (max_json_nesting), a key given twice in one object refused rather
/// than silently overridden, and every parser failure (syntax, encoding, a number beyond
/// double's range) an InvalidArgumentError naming the file. fuzz/config_fuzzer.cpp feeds it bytes.

#include <filesystem>
#include <string_view>

#include <nlohmann/json.hpp>

namespace twincal {

/// The document of `text`, a file called `name` in messages.
/// @throws InvalidArgumentError naming `name` (too deep, a repeated key, not JSON).
[[nodiscard]] nlohmann::json parse_config_text(std::string_view text, std::string_view name);

/// parse_config_text() of the file at `path`.
/// @throws InvalidArgumentError naming the path, also when it cannot be read.
[[nodiscard]] nlohmann::json read_config_file(const std::filesystem::path& path);

}  // namespace twincal
