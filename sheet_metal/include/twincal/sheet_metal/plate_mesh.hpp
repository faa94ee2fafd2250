#pragma once
/// @file
/// `PlateMesh`: a structured mesh of equal rectangles on a flat plate in the xy-plane.
///
/// Nodes are numbered row by row, node(i, j) = j · (nx + 1) + i for column i ∈ [0, nx] and row
/// j ∈ [0, ny]; element (i, j) has the corners node(i, j), node(i+1, j), node(i+1, j+1),
/// node(i, j+1) (counter-clockwise). Each node carries three degrees of freedom in the order
/// (w, θx, θy): the out-of-plane displacement and the rotations about the x- and y-axes, with
/// θx = ∂w/∂y and θy = −∂w/∂x (right-hand rule). Coordinates are in mm.

#include <optional>
#include <string>

#include "twincal/core/eigen.hpp"

namespace twincal {

class PlateMesh {
 public:
  static constexpr Index dofs_per_node = 3;

  /// A mesh of `nx` × `ny` elements covering [x0, x0 + nx·hx] × [y0, y0 + ny·hy].
  /// @throws InvalidArgumentError when a count is < 1 or a size is not finite and > 0.
  PlateMesh(Index nx, Index ny, double hx, double hy, double x0 = 0.0, double y0 = 0.0);

  [[nodiscard]] Index elements_x() const noexcept { return nx_; }
  [[nodiscard]] Index elements_y() const noexcept { return ny_; }
  [[nodiscard]] Index element_count() const noexcept { return nx_ * ny_; }
  [[nodiscard]] Index node_count() const noexcept { return (nx_ + 1) * (ny_ + 1); }
  [[nodiscard]] Index dof_count() const noexcept { return dofs_per_node * node_count(); }
  [[nodiscard]] double element_width() const noexcept { return hx_; }
  [[nodiscard]] double element_height() const noexcept { return hy_; }
  [[nodiscard]] double origin_x() const noexcept { return x0_; }
  [[nodiscard]] double origin_y() const noexcept { return y0_; }
  [[nodiscard]] double width() const noexcept { return static_cast<double>(nx_) * hx_; }
  [[nodiscard]] double height() const noexcept { return static_cast<double>(ny_) * hy_; }

  [[nodiscard]] Index node(Index i, Index j) const noexcept { return j * (nx_ + 1) + i; }
  [[nodiscard]] Index column_of(Index node) const noexcept { return node % (nx_ + 1); }
  [[nodiscard]] Index row_of(Index node) const noexcept { return node / (nx_ + 1); }
  [[nodiscard]] double x(Index node) const noexcept {
    return x0_ + static_cast<double>(column_of(node)) * hx_;
  }
  [[nodiscard]] double y(Index node) const noexcept {
    return y0_ + static_cast<double>(row_of(node)) * hy_;
  }
  /// Global dof of component `component` (0 = w, 1 = θx, 2 = θy) at `node`.
  [[nodiscard]] static Index dof(Index node, Index component) noexcept {
    return dofs_per_node * node + component;
  }
  /// The four corner nodes of element (i, j), counter-clockwise from (i, j).
  [[nodiscard]] Eigen::Matrix<Index, 4, 1> element_nodes(Index i, Index j) const noexcept;

  /// The node at (x, y), or nothing when no node lies within `tolerance` mm of it.
  [[nodiscard]] std::optional<Index> find_node(double x, double y,
                                               double tolerance = 1e-6) const noexcept;
  /// The node at (x, y).
  /// @throws InvalidArgumentError naming `what` when no node lies within 1e-6 mm of the point.
  [[nodiscard]] Index node_at(double x, double y, const std::string& what) const;
  /// Whether (x, y) lies on the plate (closed rectangle, with `tolerance`).
  [[nodiscard]] bool contains(double x, double y, double tolerance = 1e-6) const noexcept;

 private:
  Index nx_;
  Index ny_;
  double hx_;
  double hy_;
  double x0_;
  double y0_;
};

}  // namespace twincal
