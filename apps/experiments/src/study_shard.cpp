#include "twincal/experiments/study_shard.hpp"

#include <charconv>

#include <fmt/format.h>

#include "twincal/core/error.hpp"
#include "twincal/core/options.hpp"

namespace twincal {

std::optional<std::string> StudyShard::validate() const {
  return first_problem({rule::at_least("count", count, Index{1}),
                        rule::check(index >= 0 && index < count, "index", index,
                                    "must lie in [0, count) = [0, {})", count)});
}

StudyShard parse_study_shard(std::string_view text, std::string_view field) {
  const auto whole_integer = [](std::string_view part, Index& value) {
    const auto [end, error] = std::from_chars(part.data(), part.data() + part.size(), value);
    return error == std::errc() && end == part.data() + part.size() && !part.empty();
  };
  const std::size_t slash = text.find('/');
  StudyShard shard;
  if (slash == std::string_view::npos || !whole_integer(text.substr(0, slash), shard.index) ||
      !whole_integer(text.substr(slash + 1), shard.count)) {
    throw InvalidArgumentError(
        std::string(field),
        fmt::format("{}: value is \"{}\"; rule: must be i/N, two integers (shard i of N, "
                    "0 <= i < N)",
                    field, text));
  }
  if (std::optional<std::string> problem = shard.validate()) {
    throw InvalidArgumentError(std::string(field),
                               fmt::format("{}: value is \"{}\": {}", field, text, *problem));
  }
  return shard;
}

}  // namespace twincal
