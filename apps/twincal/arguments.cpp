#include "arguments.hpp"

#include <charconv>
#include <system_error>
#include <utility>

#include <fmt/format.h>

#include "twincal/core/error.hpp"

namespace twincal::cli {
namespace {

template <typename T>
T parse_number(std::string_view name, const std::string& text) {
  T value{};
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc{} || end != text.data() + text.size()) {
    throw InvalidArgumentError(std::string(name),
                               fmt::format("--{}: is \"{}\"; rule: must be a number", name, text));
  }
  return value;
}

}  // namespace

Arguments::Arguments(std::span<const std::string> args, std::set<std::string, std::less<>> flags)
    : flags_(std::move(flags)) {
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& arg = args[i];
    if (!arg.starts_with("--") || arg.size() == 2) {
      throw InvalidArgumentError("arguments",
                                 fmt::format("argument \"{}\": is not an option; rule: options are "
                                             "--name value or --name=value (see --help)",
                                             arg));
    }
    std::string name = arg.substr(2);
    const std::size_t equals = name.find('=');
    const std::string key = name.substr(0, equals);
    if (values_.contains(key) || given_flags_.contains(key)) {
      // `--runs 2 --runs 3` is a mistake, not an override: refuse it rather than pick one.
      throw InvalidArgumentError(
          key, fmt::format("--{}: is given more than once; rule: each option at most once", key));
    }
    if (equals != std::string::npos) {
      values_[key] = name.substr(equals + 1);
    } else if (flags_.contains(name)) {
      given_flags_.insert(name);
    } else if (i + 1 < args.size()) {
      values_[name] = args[++i];
    } else {
      throw InvalidArgumentError(
          name, fmt::format("--{}: has no value; rule: write --{} <value>", name, name));
    }
  }
}

bool Arguments::flag(std::string_view name) {
  read_.emplace(name);
  return given_flags_.contains(name);
}

std::optional<std::string> Arguments::text(std::string_view name) {
  read_.emplace(name);
  const auto it = values_.find(name);
  return it == values_.end() ? std::nullopt : std::optional(it->second);
}

std::optional<Index> Arguments::integer(std::string_view name) {
  const std::optional<std::string> value = text(name);
  return value ? std::optional(parse_number<Index>(name, *value)) : std::nullopt;
}

std::optional<std::uint64_t> Arguments::seed(std::string_view name) {
  const std::optional<std::string> value = text(name);
  return value ? std::optional(parse_number<std::uint64_t>(name, *value)) : std::nullopt;
}

std::optional<double> Arguments::real(std::string_view name) {
  const std::optional<std::string> value = text(name);
  return value ? std::optional(parse_number<double>(name, *value)) : std::nullopt;
}

void Arguments::require_all_read() const {
  for (const auto& [name, value] : values_) {
    if (!read_.contains(name)) {
      throw InvalidArgumentError(
          name, fmt::format("--{}: is not an option of this command; rule: see --help", name));
    }
  }
  for (const std::string& name : given_flags_) {
    if (!read_.contains(name)) {
      throw InvalidArgumentError(
          name, fmt::format("--{}: is not an option of this command; rule: see --help", name));
    }
  }
}

std::vector<std::string_view> split_commas(std::string_view list) {
  std::vector<std::string_view> items;
  std::size_t begin = 0;
  while (begin <= list.size()) {
    const std::size_t end = std::min(list.find(',', begin), list.size());
    items.push_back(list.substr(begin, end - begin));
    begin = end + 1;
  }
  return items;
}

}  // namespace twincal::cli
