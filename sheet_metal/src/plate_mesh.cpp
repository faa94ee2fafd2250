#include "twincal/sheet_metal/plate_mesh.hpp"

#include <cmath>
#include <string>

#include <fmt/format.h>

#include "twincal/core/error.hpp"
#include "twincal/core/validate.hpp"

namespace twincal {

namespace {

void require_size(std::string_view name, double value) {
  if (value > 0.0 && std::isfinite(value)) return;
  throw InvalidArgumentError(std::string(name),
                             fmt::format("{}: is {}; rule: must be finite and > 0", name, value));
}

}  // namespace

PlateMesh::PlateMesh(Index nx, Index ny, double hx, double hy, double x0, double y0)
    : nx_(nx), ny_(ny), hx_(hx), hy_(hy), x0_(x0), y0_(y0) {
  if (nx < 1 || ny < 1) {
    throw InvalidArgumentError(
        "elements", fmt::format("elements: are {} x {}; rule: both must be >= 1", nx, ny));
  }
  require_size("element width", hx);
  require_size("element height", hy);
  require_finite("origin x", x0);
  require_finite("origin y", y0);
}

Eigen::Matrix<Index, 4, 1> PlateMesh::element_nodes(Index i, Index j) const noexcept {
  Eigen::Matrix<Index, 4, 1> nodes;
  nodes << node(i, j), node(i + 1, j), node(i + 1, j + 1), node(i, j + 1);
  return nodes;
}

std::optional<Index> PlateMesh::find_node(double x, double y, double tolerance) const noexcept {
  const double fi = (x - x0_) / hx_;
  const double fj = (y - y0_) / hy_;
  const double ri = std::round(fi);
  const double rj = std::round(fj);
  if (ri < 0.0 || rj < 0.0 || ri > static_cast<double>(nx_) || rj > static_cast<double>(ny_)) {
    return std::nullopt;
  }
  if (std::abs(fi - ri) * hx_ > tolerance || std::abs(fj - rj) * hy_ > tolerance) {
    return std::nullopt;
  }
  return node(static_cast<Index>(ri), static_cast<Index>(rj));
}

Index PlateMesh::node_at(double x, double y, const std::string& what) const {
  if (const std::optional<Index> found = find_node(x, y)) return *found;
  throw InvalidArgumentError(
      what, fmt::format("{}: point ({}, {}) mm is not a node; rule: must lie on the mesh grid "
                        "[{}, {}] x [{}, {}] with spacing {} x {} mm",
                        what, x, y, x0_, x0_ + width(), y0_, y0_ + height(), hx_, hy_));
}

bool PlateMesh::contains(double x, double y, double tolerance) const noexcept {
  return x >= x0_ - tolerance && x <= x0_ + width() + tolerance && y >= y0_ - tolerance &&
         y <= y0_ + height() + tolerance;
}

}  // namespace twincal
