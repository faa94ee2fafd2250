#include "twincal/sheet_metal/sheet_metal_process.hpp"

#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "twincal/core/options.hpp"
#include "twincal/core/validate.hpp"

namespace twincal {

namespace {

using SparseMatrix = Eigen::SparseMatrix<double>;

SparseMatrix block_diagonal(const SparseMatrix& a, const SparseMatrix& b) {
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(static_cast<std::size_t>(a.nonZeros() + b.nonZeros()));
  for (Index k = 0; k < a.outerSize(); ++k) {
    for (SparseMatrix::InnerIterator it(a, k); it; ++it) {
      triplets.emplace_back(it.row(), it.col(), it.value());
    }
  }
  for (Index k = 0; k < b.outerSize(); ++k) {
    for (SparseMatrix::InnerIterator it(b, k); it; ++it) {
      triplets.emplace_back(a.rows() + it.row(), a.cols() + it.col(), it.value());
    }
  }
  SparseMatrix m(a.rows() + b.rows(), a.cols() + b.cols());
  m.setFromTriplets(triplets.begin(), triplets.end());
  return m;
}

SheetMetalLayout validated(SheetMetalLayout layout) {
  require_valid("layout", layout);
  return layout;
}

std::vector<Index> nodes_of(const std::vector<LayoutPoint>& points, const PlateMesh& upper,
                            const PlateMesh& lower, std::string_view what) {
  std::vector<Index> nodes;
  nodes.reserve(points.size());
  for (const LayoutPoint& p : points) {
    const PlateMesh& mesh = p.part == SheetMetalPart::upper ? upper : lower;
    nodes.push_back(mesh.node_at(p.x, p.y, fmt::format("{} {}", what, p.name)));
  }
  return nodes;
}

std::vector<Index> weld_nodes_of(const std::vector<Vector<2>>& welds, const PlateMesh& mesh) {
  std::vector<Index> nodes;
  nodes.reserve(welds.size());
  for (std::size_t j = 0; j < welds.size(); ++j) {
    nodes.push_back(mesh.node_at(welds[j](0), welds[j](1), fmt::format("weld {}", j)));
  }
  return nodes;
}

}  // namespace

SheetMetalProcess::SheetMetalProcess(SheetMetalLayout layout, const PlateSection& section)
    : layout_(validated(std::move(layout))),
      upper_(layout_.mesh(SheetMetalPart::upper), section),
      lower_(layout_.mesh(SheetMetalPart::lower), section),
      stiffness_(block_diagonal(upper_.stiffness(), lower_.stiffness())),
      locator_nodes_(nodes_of(layout_.locators, upper_.mesh(), lower_.mesh(), "locator")),
      key_nodes_(nodes_of(layout_.key_points, upper_.mesh(), lower_.mesh(), "key point")),
      support_nodes_(nodes_of(layout_.supports, upper_.mesh(), lower_.mesh(), "support")),
      upper_weld_nodes_(weld_nodes_of(layout_.welds, upper_.mesh())),
      lower_weld_nodes_(weld_nodes_of(layout_.welds, lower_.mesh())),
      tied_components_(tied_components(layout_.weld_tie)),
      weld_stage_(stiffness_, weld_constraints()),
      release_stage_(stiffness_, release_constraints()) {}

std::vector<LinearConstraint> SheetMetalProcess::weld_constraints() const {
  // Order: locators (d), then one gap closure per weld (upper w tied to lower w).
  std::vector<LinearConstraint> c;
  for (std::size_t k = 0; k < locator_nodes_.size(); ++k) {
    c.push_back({global_dof(layout_.locators[k].part, PlateMesh::dof(locator_nodes_[k], 0))});
  }
  for (std::size_t j = 0; j < upper_weld_nodes_.size(); ++j) {
    c.push_back({global_dof(SheetMetalPart::upper, PlateMesh::dof(upper_weld_nodes_[j], 0)),
                 global_dof(SheetMetalPart::lower, PlateMesh::dof(lower_weld_nodes_[j], 0))});
  }
  return c;
}

std::vector<LinearConstraint> SheetMetalProcess::release_constraints() const {
  // Order: weld ties (the tied components of each weld), then the final supports.
  std::vector<LinearConstraint> c;
  for (std::size_t j = 0; j < upper_weld_nodes_.size(); ++j) {
    for (const Index component : tied_components_) {
      c.push_back(
          {global_dof(SheetMetalPart::upper, PlateMesh::dof(upper_weld_nodes_[j], component)),
           global_dof(SheetMetalPart::lower, PlateMesh::dof(lower_weld_nodes_[j], component))});
    }
  }
  const bool on_locators = layout_.final_support == FinalSupport::adjusted_locators;
  const std::vector<LayoutPoint>& points = on_locators ? layout_.locators : layout_.supports;
  const std::vector<Index>& nodes = on_locators ? locator_nodes_ : support_nodes_;
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    c.push_back({global_dof(points[k].part, PlateMesh::dof(nodes[k], 0))});
  }
  return c;
}

void SheetMetalProcess::require_inputs(const Eigen::Ref<const VectorX>& upper_free,
                                       const Eigen::Ref<const VectorX>& lower_free,
                                       const Eigen::Ref<const VectorX>& control) const {
  require_dimension("upper_free", upper_free.size(), dof_count(SheetMetalPart::upper));
  require_dimension("lower_free", lower_free.size(), dof_count(SheetMetalPart::lower));
  require_dimension("control", control.size(), control_dimension());
}

double SheetMetalProcess::free_w(SheetMetalPart part, Index node,
                                 const Eigen::Ref<const VectorX>& upper_free,
                                 const Eigen::Ref<const VectorX>& lower_free) const {
  const Index dof = PlateMesh::dof(node, 0);
  return part == SheetMetalPart::upper ? upper_free(dof) : lower_free(dof);
}

VectorX SheetMetalProcess::welded_state(const Eigen::Ref<const VectorX>& upper_free,
                                        const Eigen::Ref<const VectorX>& lower_free,
                                        const Eigen::Ref<const VectorX>& control) const {
  require_inputs(upper_free, lower_free, control);
  VectorX values(weld_stage_.constraint_count());
  Index r = 0;
  for (std::size_t k = 0; k < locator_nodes_.size(); ++k) {
    values(r++) = control(static_cast<Index>(k)) -
                  free_w(layout_.locators[k].part, locator_nodes_[k], upper_free, lower_free);
  }
  for (std::size_t j = 0; j < upper_weld_nodes_.size(); ++j) {
    values(r++) = lower_free(PlateMesh::dof(lower_weld_nodes_[j], 0)) -
                  upper_free(PlateMesh::dof(upper_weld_nodes_[j], 0));
  }
  return weld_stage_.solve(values);
}

VectorX SheetMetalProcess::released_state(const Eigen::Ref<const VectorX>& upper_free,
                                          const Eigen::Ref<const VectorX>& lower_free,
                                          const Eigen::Ref<const VectorX>& control) const {
  const VectorX welded = welded_state(upper_free, lower_free, control);
  VectorX values(release_stage_.constraint_count());
  Index r = 0;
  for (std::size_t j = 0; j < upper_weld_nodes_.size(); ++j) {
    for (const Index component : tied_components_) {
      values(r++) = welded(global_dof(SheetMetalPart::upper,
                                      PlateMesh::dof(upper_weld_nodes_[j], component))) -
                    welded(global_dof(SheetMetalPart::lower,
                                      PlateMesh::dof(lower_weld_nodes_[j], component)));
    }
  }
  if (layout_.final_support == FinalSupport::adjusted_locators) {
    for (std::size_t k = 0; k < locator_nodes_.size(); ++k) {
      values(r++) = control(static_cast<Index>(k)) -
                    free_w(layout_.locators[k].part, locator_nodes_[k], upper_free, lower_free);
    }
  } else {
    for (std::size_t s = 0; s < support_nodes_.size(); ++s) {
      values(r++) = -free_w(layout_.supports[s].part, support_nodes_[s], upper_free, lower_free);
    }
  }
  return release_stage_.solve(values);
}

VectorX SheetMetalProcess::key_deviation(const Eigen::Ref<const VectorX>& upper_free,
                                         const Eigen::Ref<const VectorX>& lower_free,
                                         const Eigen::Ref<const VectorX>& control) const {
  const VectorX released = released_state(upper_free, lower_free, control);
  VectorX y(key_point_count());
  for (std::size_t i = 0; i < key_nodes_.size(); ++i) {
    const SheetMetalPart part = layout_.key_points[i].part;
    const Index dof = PlateMesh::dof(key_nodes_[i], 0);
    y(static_cast<Index>(i)) =
        free_w(part, key_nodes_[i], upper_free, lower_free) + released(global_dof(part, dof));
  }
  return y;
}

MatrixX SheetMetalProcess::control_influence() const {
  const Index d = control_dimension();
  const VectorX upper_zero = VectorX::Zero(dof_count(SheetMetalPart::upper));
  const VectorX lower_zero = VectorX::Zero(dof_count(SheetMetalPart::lower));
  MatrixX influence(key_point_count(), d);
  for (Index k = 0; k < d; ++k) {
    influence.col(k) = key_deviation(upper_zero, lower_zero, VectorX::Unit(d, k));
  }
  return influence;
}

}  // namespace twincal
