#include "twincal/sheet_metal/contact_pairs.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

#include "twincal/core/options.hpp"
#include "twincal/sheet_metal/plate_mesh.hpp"

namespace twincal {

std::vector<ContactPair> flange_contact_pairs(const SheetMetalLayout& layout) {
  require_valid("layout", layout);
  const PlateMesh upper = layout.mesh(SheetMetalPart::upper);
  const PlateMesh lower = layout.mesh(SheetMetalPart::lower);
  // The grid is shared (validated), so walking the upper mesh's nodes and looking each up in
  // the lower mesh visits exactly the overlap.
  std::vector<Index> weld_nodes;
  weld_nodes.reserve(layout.welds.size());
  for (const Vector<2>& weld : layout.welds) {
    weld_nodes.push_back(upper.node_at(weld(0), weld(1), "weld"));
  }
  std::vector<ContactPair> pairs;
  for (Index node = 0; node < upper.node_count(); ++node) {
    const double x = upper.x(node);
    const double y = upper.y(node);
    const std::optional<Index> facing = lower.find_node(x, y);
    if (!facing) continue;
    if (std::find(weld_nodes.begin(), weld_nodes.end(), node) != weld_nodes.end()) continue;
    pairs.push_back({node, *facing, x, y});
  }
  return pairs;
}

}  // namespace twincal
