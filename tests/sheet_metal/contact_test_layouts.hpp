#pragma once
// Coarse lap joints for the contact tests (SheetMetalLayout::lap_joint): 40 mm elements, two 400 ×
// 200 mm parts overlapping in an 80 mm flange (rows y = 120, 160, 200) with five welds on its
// middle row, three locators per part and key points in and away from the flange. Small enough that
// a twin builds in milliseconds; `door_like` releases onto a nominal frame with rotation-locking
// welds (the door's choices), otherwise the assembly stays on its adjusted locators (the body's).

#include <cstdint>

#include "twincal/sheet_metal/sheet_metal_layout.hpp"
#include "twincal/sheet_metal/sheet_metal_twin.hpp"

namespace twincal::contact_test_layouts {

inline SheetMetalLayout small_lap_joint(bool door_like) {
  SheetMetalLayout layout = SheetMetalLayout::lap_joint();
  layout.name = door_like ? "small-door" : "small-body";
  if (door_like) {
    layout.supports = layout.supports_at({"L1", "L2", "L3", "U1", "U2", "U3"});
    layout.final_support = FinalSupport::nominal_frame;
    layout.weld_tie = WeldTie::translation_and_rotation;
  }
  return layout;
}

/// The linear twin of small_lap_joint(door_like) over 2 × 2 seeded parts.
inline SheetMetalTwin small_lap_joint_twin(bool door_like, std::uint64_t seed) {
  SheetMetalTwinOptions options;
  options.upper_parts = 2;
  options.lower_parts = 2;
  return SheetMetalTwin::generate(small_lap_joint(door_like), options, seed);
}

}  // namespace twincal::contact_test_layouts
