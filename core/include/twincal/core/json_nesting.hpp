#pragma once
/// @file
/// `json_nesting_depth(text)` and `require_json_nesting(text, name)`: how deeply a JSON text nests
/// its arrays and objects, counted on the raw bytes before any parser sees them. Every JSON text
/// twincal reads from outside — a config file, a `twincal serve` request, a twin's reply — is
/// checked against `max_json_nesting` first: a parser and the code that walks its result recurse
/// once per level, so a text of `[[[[…` alone could otherwise exhaust the stack (measured: 200 000
/// levels in a config ended `twincal run` with SIGSEGV). Brackets inside strings do not count;
/// the text need not be valid JSON (the parser judges that afterwards).

#include <cstddef>
#include <string_view>

#include <fmt/format.h>

#include "twincal/core/eigen.hpp"
#include "twincal/core/error.hpp"

namespace twincal {

/// The deepest nesting twincal accepts in a JSON text (a config nests 4 levels, a request 3).
inline constexpr Index max_json_nesting = 64;

/// The largest number of arrays and objects open at once in `text`, outside strings (a
/// backslash escapes the next byte inside a string).
[[nodiscard]] constexpr Index json_nesting_depth(std::string_view text) noexcept {
  Index depth = 0;
  Index deepest = 0;
  bool in_string = false;
  bool escaped = false;
  for (const char c : text) {
    if (in_string) {
      if (escaped) {
        escaped = false;
      } else if (c == '\\') {
        escaped = true;
      } else if (c == '"') {
        in_string = false;
      }
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      ++depth;
      if (depth > deepest) deepest = depth;
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
  return deepest;
}

/// @throws InvalidArgumentError naming `name`, the depth found and the limit, when `text` nests
///         deeper than `max_depth`.
inline void require_json_nesting(std::string_view text, std::string_view name,
                                 Index max_depth = max_json_nesting) {
  const Index depth = json_nesting_depth(text);
  if (depth <= max_depth) return;
  throw InvalidArgumentError(
      std::string(name), fmt::format("{}: nests {} levels of arrays and objects; rule: at most {}",
                                     name, depth, max_depth));
}

}  // namespace twincal
