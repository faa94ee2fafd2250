#include "twincal/calculix/calculix_results.hpp"

#include <cmath>
#include <cstdlib>
#include <string>

#include <fmt/format.h>

#include "twincal/calculix/calculix_error.hpp"

namespace twincal {
namespace {

constexpr std::string_view block_heading = "displacements (vx,vy,vz) for set";

std::string_view next_line(std::string_view& text) {
  const std::size_t end = text.find('\n');
  const std::string_view line = text.substr(0, end);
  text.remove_prefix(end == std::string_view::npos ? text.size() : end + 1);
  return line;
}

bool blank(std::string_view line) {
  return line.find_first_not_of(" \t\r") == std::string_view::npos;
}

// strtod on a copy: the view is not null-terminated. Returns false unless the whole field is a
// finite number.
bool parse_fields(std::string_view line, std::vector<double>& fields) {
  fields.clear();
  const std::string copy(line);
  const char* cursor = copy.c_str();
  while (true) {
    while (*cursor == ' ' || *cursor == '\t' || *cursor == '\r') ++cursor;
    if (*cursor == '\0') return true;
    char* end = nullptr;
    const double value = std::strtod(cursor, &end);
    if (end == cursor || !std::isfinite(value)) return false;
    fields.push_back(value);
    cursor = end;
  }
}

}  // namespace

std::vector<NodePrint> read_displacement_prints(std::string_view dat) {
  std::vector<NodePrint> prints;
  std::vector<double> fields;
  while (!dat.empty()) {
    const std::string_view line = next_line(dat);
    const std::size_t heading = line.find(block_heading);
    if (heading == std::string_view::npos) continue;
    const std::size_t at = line.rfind("time");
    if (at == std::string_view::npos || !parse_fields(line.substr(at + 4), fields) ||
        fields.size() != 1) {
      throw CalculixError(CalculixFailure::unreadable_results,
                          fmt::format("calculix results: heading '{}' has no time; rule: "
                                      "'… and time <t>'",
                                      line),
                          "");
    }
    NodePrint print;
    print.time = fields.front();
    // A blank line follows the heading; the block ends at the next blank line or heading.
    while (!dat.empty() && blank(dat.substr(0, dat.find('\n')))) next_line(dat);
    while (!dat.empty()) {
      const std::string_view row = dat.substr(0, dat.find('\n'));
      if (blank(row) || row.find(block_heading) != std::string_view::npos) break;
      next_line(dat);
      if (!parse_fields(row, fields) || fields.size() != 4 || fields[0] < 1.0 ||
          fields[0] != std::floor(fields[0])) {
        throw CalculixError(
            CalculixFailure::unreadable_results,
            fmt::format("calculix results: row '{}'; rule: 'node vx vy vz', finite numbers", row),
            "");
      }
      print.nodes.push_back(static_cast<Index>(fields[0]));
      print.displacements.emplace_back(fields[1], fields[2], fields[3]);
    }
    prints.push_back(std::move(print));
  }
  return prints;
}

std::vector<NodePrint> release_prints(const std::vector<NodePrint>& prints) {
  std::vector<NodePrint> releases;
  // Prints come in time order; step 2c + 2 ends at total time 2c + 2 (each step lasts 1).
  for (const NodePrint& print : prints) {
    const double expected = 2.0 * static_cast<double>(releases.size() + 1);
    if (std::abs(print.time - expected) <= 1e-9 * expected) releases.push_back(print);
  }
  return releases;
}

}  // namespace twincal
