#include "twincal/sheet_metal/part_deviation_file.hpp"

#include <charconv>
#include <cmath>
#include <fstream>
#include <istream>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "twincal/core/error.hpp"
#include "twincal/core/validate.hpp"

namespace twincal {

namespace {

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '\r')) {
    s.remove_prefix(1);
  }
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) {
    s.remove_suffix(1);
  }
  return s;
}

std::vector<std::string_view> split(std::string_view line) {
  std::vector<std::string_view> fields;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    fields.push_back(trim(line.substr(start, comma - start)));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return fields;
}

[[noreturn]] void fail(std::string_view name, std::size_t line, const std::string& problem) {
  throw InvalidArgumentError(std::string(name), fmt::format("{}:{}: {}", name, line, problem));
}

}  // namespace

VectorX PartDeviationFile::with_slopes(const PlateMesh& mesh, const Eigen::Ref<const VectorX>& w) {
  require_dimension("w", w.size(), mesh.node_count());
  const Index nx = mesh.elements_x();
  const Index ny = mesh.elements_y();
  // Second-order derivative along one grid line: central inside, three-point one-sided at the
  // ends, two-point when the line has a single element.
  const auto derivative = [](auto value, Index i, Index last, double h) {
    if (last == 1) return (value(1) - value(0)) / h;
    if (i == 0) return (-3.0 * value(0) + 4.0 * value(1) - value(2)) / (2.0 * h);
    if (i == last) return (3.0 * value(last) - 4.0 * value(last - 1) + value(last - 2)) / (2.0 * h);
    return (value(i + 1) - value(i - 1)) / (2.0 * h);
  };
  VectorX deviations(mesh.dof_count());
  for (Index j = 0; j <= ny; ++j) {
    for (Index i = 0; i <= nx; ++i) {
      const Index node = mesh.node(i, j);
      const double wx =
          derivative([&](Index k) { return w(mesh.node(k, j)); }, i, nx, mesh.element_width());
      const double wy =
          derivative([&](Index k) { return w(mesh.node(i, k)); }, j, ny, mesh.element_height());
      deviations(PlateMesh::dof(node, 0)) = w(node);
      deviations(PlateMesh::dof(node, 1)) = wy;
      deviations(PlateMesh::dof(node, 2)) = -wx;
    }
  }
  return deviations;
}

VectorX PartDeviationFile::read(const std::filesystem::path& path, const PlateMesh& mesh) {
  std::ifstream in(path);
  if (!in) {
    fail(path.string(), 0, "cannot open the file; rule: must be a readable part deviation file");
  }
  return read(in, path.string(), mesh);
}

VectorX PartDeviationFile::read(std::istream& in, std::string_view name, const PlateMesh& mesh) {
  std::string line;
  std::size_t line_number = 0;
  Index columns = 0;
  std::vector<bool> seen(static_cast<std::size_t>(mesh.node_count()), false);
  VectorX values = VectorX::Zero(mesh.dof_count());
  Index rows = 0;
  while (std::getline(in, line)) {
    ++line_number;
    const std::string_view text = trim(line);
    if (text.empty() || text.front() == '#') continue;
    const std::vector<std::string_view> fields = split(text);
    if (columns == 0) {
      if (text == "x,y,w") {
        columns = 3;
      } else if (text == "x,y,w,theta_x,theta_y") {
        columns = 5;
      } else {
        fail(name, line_number,
             fmt::format("header is '{}'; rule: must be 'x,y,w' or 'x,y,w,theta_x,theta_y'", text));
      }
      continue;
    }
    if (static_cast<Index>(fields.size()) != columns) {
      fail(name, line_number,
           fmt::format("row has {} fields; rule: must have {}", fields.size(), columns));
    }
    std::array<double, 5> numbers{};
    for (std::size_t k = 0; k < fields.size(); ++k) {
      const std::string_view field = fields[k];
      const auto [end, error] =
          std::from_chars(field.data(), field.data() + field.size(), numbers[k]);
      if (error != std::errc() || end != field.data() + field.size() ||
          !std::isfinite(numbers[k])) {
        fail(name, line_number,
             fmt::format("field {} is '{}'; rule: must be a finite number", k + 1, field));
      }
    }
    const std::optional<Index> node = mesh.find_node(numbers[0], numbers[1], 1e-3);
    if (!node) {
      fail(name, line_number,
           fmt::format("point ({}, {}) is not a mesh node; rule: must match a node of the "
                       "{} x {} mesh within 1e-3 mm",
                       numbers[0], numbers[1], mesh.elements_x(), mesh.elements_y()));
    }
    if (seen[static_cast<std::size_t>(*node)]) {
      fail(name, line_number,
           fmt::format("node at ({}, {}) appears again; rule: each node exactly once", numbers[0],
                       numbers[1]));
    }
    seen[static_cast<std::size_t>(*node)] = true;
    ++rows;
    for (Index c = 0; c < columns - 2; ++c) {
      values(PlateMesh::dof(*node, c)) = numbers[static_cast<std::size_t>(2 + c)];
    }
  }
  if (columns == 0) fail(name, line_number, "no header; rule: the file must start with one");
  if (rows != mesh.node_count()) {
    fail(name, line_number,
         fmt::format("has {} node rows; rule: must have one per node ({})", rows,
                     mesh.node_count()));
  }
  if (columns == 5) return values;
  VectorX w(mesh.node_count());
  for (Index node = 0; node < mesh.node_count(); ++node) w(node) = values(PlateMesh::dof(node, 0));
  return with_slopes(mesh, w);
}

void PartDeviationFile::write(const std::filesystem::path& path, const PlateMesh& mesh,
                              const Eigen::Ref<const VectorX>& deviations) {
  require_dimension("deviations", deviations.size(), mesh.dof_count());
  std::ofstream out(path);
  if (!out) {
    throw InvalidArgumentError(
        path.string(),
        fmt::format("{}: cannot open for writing; rule: must be writable", path.string()));
  }
  out << "# twincal part deviation: w in mm, theta_x = dw/dy, theta_y = -dw/dx in rad\n";
  out << "x,y,w,theta_x,theta_y\n";
  for (Index node = 0; node < mesh.node_count(); ++node) {
    out << fmt::format("{},{},{},{},{}\n", mesh.x(node), mesh.y(node),
                       deviations(PlateMesh::dof(node, 0)), deviations(PlateMesh::dof(node, 1)),
                       deviations(PlateMesh::dof(node, 2)));
  }
  if (!out) {
    throw InvalidArgumentError(
        path.string(), fmt::format("{}: write failed; rule: must be writable", path.string()));
  }
}

}  // namespace twincal
