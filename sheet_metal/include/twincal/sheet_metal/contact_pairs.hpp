#pragma once
/// @file
/// `flange_contact_pairs`: where the two sheets of a lap joint can touch — the node-to-node
/// contact pairs of Dahlström & Lindkvist (2007). Both parts are meshed on one shared grid
/// (sheet_metal_layout.hpp), so every grid point of the overlap (the flange) is a node of the
/// upper and of the lower mesh: the two nodes face each other across the nominal gap. The weld
/// points are left out (the nugget ties them, they cannot open or penetrate); every other node
/// of the overlap, between the welds along the weld rows and beside them up to the flange's
/// edges, is a pair.

#include <vector>

#include "twincal/core/eigen.hpp"
#include "twincal/sheet_metal/sheet_metal_layout.hpp"

namespace twincal {

/// Two facing nodes, one per part, at the same in-plane position.
struct ContactPair {
  Index upper_node = 0;  ///< in layout.mesh(upper)
  Index lower_node = 0;  ///< in layout.mesh(lower)
  double x = 0.0;        ///< mm
  double y = 0.0;        ///< mm
};

/// Every grid point of the overlap of the two outlines except the welds, row by row (y, then x
/// ascending).
/// @throws InvalidArgumentError for an invalid layout (SheetMetalLayout::validate).
[[nodiscard]] std::vector<ContactPair> flange_contact_pairs(const SheetMetalLayout& layout);

}  // namespace twincal
