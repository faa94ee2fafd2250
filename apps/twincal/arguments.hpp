#pragma once
// A small command-line parser for the twincal subcommands: `--key value`, `--key=value` and
// bare flags, each read at most once by the command, and anything left over is an error.

#include <map>
#include <optional>
#include <set>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <cstdint>

#include "twincal/core/eigen.hpp"

namespace twincal::cli {

class Arguments {
 public:
  /// Parses `args` (after the subcommand). `flags` are the options that take no value.
  /// @throws InvalidArgumentError for a positional argument or a value-less option.
  Arguments(std::span<const std::string> args, std::set<std::string, std::less<>> flags);

  /// Whether the flag was given (and marks it read).
  [[nodiscard]] bool flag(std::string_view name);
  /// The value of `--name`, if given.
  [[nodiscard]] std::optional<std::string> text(std::string_view name);
  [[nodiscard]] std::optional<Index> integer(std::string_view name);
  [[nodiscard]] std::optional<std::uint64_t> seed(std::string_view name);
  [[nodiscard]] std::optional<double> real(std::string_view name);

  /// @throws InvalidArgumentError naming the first option no one read.
  void require_all_read() const;

 private:
  std::map<std::string, std::string, std::less<>> values_;
  std::set<std::string, std::less<>> flags_;
  std::set<std::string, std::less<>> given_flags_;
  std::set<std::string, std::less<>> read_;
};

/// The items of a comma-separated list ("" is one empty item, which the parsers refuse).
[[nodiscard]] std::vector<std::string_view> split_commas(std::string_view list);

}  // namespace twincal::cli
