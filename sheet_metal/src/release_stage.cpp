#include "twincal/sheet_metal/release_stage.hpp"

#include <utility>

#include "twincal/core/validate.hpp"
#include "twincal/sheet_metal/plate_mesh.hpp"

namespace twincal {

namespace {

// The constraints of SheetMetalProcess's release stage, in its order: the weld ties (the tied
// components of each weld, upper slave, lower master), then the final supports.
std::vector<LinearConstraint> release_constraints(const SheetMetalProcess& process,
                                                  const std::vector<Index>& components) {
  const SheetMetalLayout& layout = process.layout();
  const std::vector<Index>& upper_welds = process.weld_nodes(SheetMetalPart::upper);
  const std::vector<Index>& lower_welds = process.weld_nodes(SheetMetalPart::lower);
  std::vector<LinearConstraint> c;
  for (std::size_t j = 0; j < upper_welds.size(); ++j) {
    for (const Index component : components) {
      c.push_back(
          {process.global_dof(SheetMetalPart::upper, PlateMesh::dof(upper_welds[j], component)),
           process.global_dof(SheetMetalPart::lower, PlateMesh::dof(lower_welds[j], component))});
    }
  }
  const bool on_locators = layout.final_support == FinalSupport::adjusted_locators;
  const std::vector<LayoutPoint>& points = on_locators ? layout.locators : layout.supports;
  const std::vector<Index>& nodes = on_locators ? process.locator_nodes() : process.support_nodes();
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    c.push_back({process.global_dof(points[k].part, PlateMesh::dof(nodes[k], 0))});
  }
  return c;
}

}  // namespace

ReleaseStage::ReleaseStage(const SheetMetalProcess& process)
    : solver_(process.stiffness(),
              release_constraints(process, tied_components(process.layout().weld_tie))),
      tied_components_(tied_components(process.layout().weld_tie)),
      prescribed_(static_cast<std::size_t>(process.stiffness().rows()), false) {
  for (const LinearConstraint& c : solver_.constraints()) {
    if (c.master < 0) prescribed_[static_cast<std::size_t>(c.slave)] = true;
  }
}

VectorX ReleaseStage::response(const Eigen::Ref<const VectorX>& load) const {
  require_dimension("load", load.size(), dof_count());
  return solver_.solve(VectorX::Zero(solver_.constraint_count()), load);
}

bool ReleaseStage::prescribed(Index dof) const {
  require_in_range("dof", static_cast<double>(dof), 0.0, static_cast<double>(dof_count() - 1));
  return prescribed_[static_cast<std::size_t>(dof)];
}

VectorX ReleaseStage::released_state(const SheetMetalProcess& process,
                                     const Eigen::Ref<const VectorX>& upper_free,
                                     const Eigen::Ref<const VectorX>& lower_free,
                                     const Eigen::Ref<const VectorX>& control) const {
  require_dimension("process dofs", process.stiffness().rows(), dof_count());
  const VectorX welded = process.welded_state(upper_free, lower_free, control);
  const SheetMetalLayout& layout = process.layout();
  const std::vector<Index>& upper_welds = process.weld_nodes(SheetMetalPart::upper);
  const std::vector<Index>& lower_welds = process.weld_nodes(SheetMetalPart::lower);
  // The values in the order of the constraints: each weld keeps the relative displacement (and
  // rotation) it was formed with; supports hold nominal (+ u on adjusted locators) against the
  // free shape.
  VectorX values(solver_.constraint_count());
  Index r = 0;
  for (std::size_t j = 0; j < upper_welds.size(); ++j) {
    for (const Index component : tied_components_) {
      values(r++) = welded(process.global_dof(SheetMetalPart::upper,
                                              PlateMesh::dof(upper_welds[j], component))) -
                    welded(process.global_dof(SheetMetalPart::lower,
                                              PlateMesh::dof(lower_welds[j], component)));
    }
  }
  const auto free_w = [&](SheetMetalPart part, Index node) {
    const Index dof = PlateMesh::dof(node, 0);
    return part == SheetMetalPart::upper ? upper_free(dof) : lower_free(dof);
  };
  if (layout.final_support == FinalSupport::adjusted_locators) {
    for (std::size_t k = 0; k < process.locator_nodes().size(); ++k) {
      values(r++) = control(static_cast<Index>(k)) -
                    free_w(layout.locators[k].part, process.locator_nodes()[k]);
    }
  } else {
    for (std::size_t s = 0; s < process.support_nodes().size(); ++s) {
      values(r++) = -free_w(layout.supports[s].part, process.support_nodes()[s]);
    }
  }
  return solver_.solve(values);
}

}  // namespace twincal
