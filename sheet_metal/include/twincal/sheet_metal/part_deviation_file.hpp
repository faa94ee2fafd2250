#pragma once
/// @file
/// `PartDeviationFile`: one part's nodal free-shape deviations as a text file, so scanned parts
/// can replace the synthetic ones.
///
/// Format (CSV, '#' starts a comment line, blank lines are skipped):
///   x,y,w                       (header: normal deviations only), or
///   x,y,w,theta_x,theta_y       (header: with slopes, θx = ∂w/∂y, θy = −∂w/∂x, in rad)
/// followed by one row per mesh node, in any order: the node's coordinates (mm, matched to the
/// mesh within 1e-3 mm) and its deviation (mm). Every node appears exactly once. Without slope
/// columns the slopes are taken from w by second-order finite differences on the grid (central
/// inside, one-sided three-point at the edges).

#include <filesystem>
#include <istream>
#include <string_view>

#include "twincal/core/eigen.hpp"
#include "twincal/sheet_metal/plate_mesh.hpp"

namespace twincal {

class PartDeviationFile {
 public:
  /// Reads the deviations of one part on `mesh` (w, θx, θy per node).
  /// @throws InvalidArgumentError naming the file and line when the file cannot be opened, the
  ///         header is unknown, a row is malformed or not finite, a point is not a node, a node
  ///         repeats or is missing.
  [[nodiscard]] static VectorX read(const std::filesystem::path& path, const PlateMesh& mesh);
  /// read() of the text in `in`, a file called `name` in messages.
  [[nodiscard]] static VectorX read(std::istream& in, std::string_view name, const PlateMesh& mesh);

  /// Writes `deviations` (w, θx, θy per node of `mesh`) with slope columns, full precision.
  /// @throws DimensionMismatchError for a wrong size; InvalidArgumentError when the file cannot
  ///         be written.
  static void write(const std::filesystem::path& path, const PlateMesh& mesh,
                    const Eigen::Ref<const VectorX>& deviations);

  /// Nodal slopes (θx, θy) from nodal w by the finite differences described above; returns the
  /// full (w, θx, θy) vector. `w` has one entry per node.
  [[nodiscard]] static VectorX with_slopes(const PlateMesh& mesh,
                                           const Eigen::Ref<const VectorX>& w);
};

}  // namespace twincal
