#include "twincal/sheet_metal/plate_model.hpp"

#include <utility>
#include <vector>

#include <Eigen/SparseCore>

#include "twincal/core/options.hpp"

namespace twincal {

namespace {

// The global dofs of element (i, j) in the element's corner/dof order.
Eigen::Matrix<Index, 12, 1> element_dofs(const PlateMesh& mesh, Index i, Index j) {
  const Eigen::Matrix<Index, 4, 1> nodes = mesh.element_nodes(i, j);
  Eigen::Matrix<Index, 12, 1> dofs;
  for (Index k = 0; k < 4; ++k) {
    for (Index c = 0; c < 3; ++c) dofs(3 * k + c) = PlateMesh::dof(nodes(k), c);
  }
  return dofs;
}

}  // namespace

PlateModel::PlateModel(PlateMesh mesh, const PlateSection& section)
    : mesh_(std::move(mesh)),
      section_(section),
      element_(mesh_.element_width(), mesh_.element_height(), section) {
  // Equal rectangles: one element matrix, scattered into the global one.
  const AcmPlateElement::Stiffness& ke = element_.stiffness();
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(static_cast<std::size_t>(mesh_.element_count() * 144));
  for (Index j = 0; j < mesh_.elements_y(); ++j) {
    for (Index i = 0; i < mesh_.elements_x(); ++i) {
      const Eigen::Matrix<Index, 12, 1> dofs = element_dofs(mesh_, i, j);
      for (Index a = 0; a < 12; ++a) {
        for (Index b = 0; b < 12; ++b) triplets.emplace_back(dofs(a), dofs(b), ke(a, b));
      }
    }
  }
  stiffness_.resize(mesh_.dof_count(), mesh_.dof_count());
  stiffness_.setFromTriplets(triplets.begin(), triplets.end());
}

VectorX PlateModel::uniform_load(double pressure) const {
  VectorX load = VectorX::Zero(mesh_.dof_count());
  const AcmPlateElement::Load fe = element_.pressure_load(pressure);
  for (Index j = 0; j < mesh_.elements_y(); ++j) {
    for (Index i = 0; i < mesh_.elements_x(); ++i) {
      const Eigen::Matrix<Index, 12, 1> dofs = element_dofs(mesh_, i, j);
      for (Index a = 0; a < 12; ++a) load(dofs(a)) += fe(a);
    }
  }
  return load;
}

VectorX PlateModel::rigid_motion(double a, double b, double c) const {
  VectorX motion(mesh_.dof_count());
  for (Index node = 0; node < mesh_.node_count(); ++node) {
    motion(PlateMesh::dof(node, 0)) = a + b * mesh_.x(node) + c * mesh_.y(node);
    motion(PlateMesh::dof(node, 1)) = c;   // θx = ∂w/∂y
    motion(PlateMesh::dof(node, 2)) = -b;  // θy = −∂w/∂x
  }
  return motion;
}

}  // namespace twincal
