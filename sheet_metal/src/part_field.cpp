#include "twincal/sheet_metal/part_field.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "twincal/core/options.hpp"

namespace twincal {

std::optional<std::string> PartFieldOptions::validate() const {
  return first_problem({rule::non_negative_finite("standard_deviation", standard_deviation),
                        rule::positive_finite("correlation_length", correlation_length),
                        rule::at_least("features", features, decltype(features){1}),
                        rule::non_negative_finite("bow", bow),
                        rule::non_negative_finite("twist", twist)});
}

PartField::PartField(const PartFieldOptions& options) : options_(options) {
  require_valid("options", options);
}

VectorX PartField::sample(const PlateMesh& mesh, RandomStream& stream) const {
  const Index n = options_.features;
  MatrixX frequencies(2, n);
  VectorX phases(n);
  for (Index k = 0; k < n; ++k) {
    frequencies(0, k) = stream.normal() / options_.correlation_length;
    frequencies(1, k) = stream.normal() / options_.correlation_length;
    phases(k) = 2.0 * std::numbers::pi * stream.uniform();
  }
  const double bow_x = options_.bow * stream.normal();
  const double bow_y = options_.bow * stream.normal();
  const double twist = options_.twist * stream.normal();

  const double amplitude = options_.standard_deviation * std::sqrt(2.0 / static_cast<double>(n));
  // Bow and twist in coordinates scaled to [−1, 1] over the part.
  const double xc = mesh.origin_x() + 0.5 * mesh.width();
  const double yc = mesh.origin_y() + 0.5 * mesh.height();
  const double sx = 2.0 / mesh.width();
  const double sy = 2.0 / mesh.height();

  VectorX deviations(mesh.dof_count());
  for (Index node = 0; node < mesh.node_count(); ++node) {
    const double x = mesh.x(node);
    const double y = mesh.y(node);
    double w = 0.0;
    double wx = 0.0;
    double wy = 0.0;
    for (Index k = 0; k < n; ++k) {
      const double arg = frequencies(0, k) * x + frequencies(1, k) * y + phases(k);
      const double s = std::sin(arg);
      w += std::cos(arg);
      wx -= frequencies(0, k) * s;
      wy -= frequencies(1, k) * s;
    }
    w *= amplitude;
    wx *= amplitude;
    wy *= amplitude;
    const double px = sx * (x - xc);
    const double py = sy * (y - yc);
    w += bow_x * px * px + bow_y * py * py + twist * px * py;
    wx += 2.0 * bow_x * px * sx + twist * sx * py;
    wy += 2.0 * bow_y * py * sy + twist * px * sy;
    deviations(PlateMesh::dof(node, 0)) = w;
    deviations(PlateMesh::dof(node, 1)) = wy;   // θx = ∂w/∂y
    deviations(PlateMesh::dof(node, 2)) = -wx;  // θy = −∂w/∂x
  }
  return deviations;
}

std::vector<VectorX> PartField::sample_parts(const PlateMesh& mesh, const RandomStream& root,
                                             std::string_view side, Index count) const {
  std::vector<VectorX> parts;
  parts.reserve(static_cast<std::size_t>(std::max<Index>(count, 0)));
  for (Index i = 0; i < count; ++i) {
    RandomStream stream = root.substream(side).substream(static_cast<std::uint64_t>(i));
    parts.push_back(sample(mesh, stream));
  }
  return parts;
}

}  // namespace twincal
