#pragma once
// Coarse lap joints for the contact tests: 40 mm elements, two 400 × 200 mm parts overlapping in
// an 80 mm flange (rows y = 120, 160, 200) with five welds on its middle row, three locators per
// part and key points in and away from the flange. Small enough that a twin builds in
// milliseconds; `door_like` releases onto a nominal frame with rotation-locking welds (the
// door's choices), otherwise the assembly stays on its adjusted locators (the body's).

#include "twincal/sheet_metal/sheet_metal_layout.hpp"

namespace twincal::contact_test_layouts {

inline SheetMetalLayout small_lap_joint(bool door_like) {
  constexpr SheetMetalPart upper = SheetMetalPart::upper;
  constexpr SheetMetalPart lower = SheetMetalPart::lower;
  SheetMetalLayout layout;
  layout.name = door_like ? "small-door" : "small-body";
  layout.element_size = 40.0;
  layout.lower = {0.0, 0.0, 400.0, 200.0};
  layout.upper = {0.0, 120.0, 400.0, 200.0};
  for (const double x : {40.0, 120.0, 200.0, 280.0, 360.0}) layout.welds.emplace_back(x, 160.0);
  layout.locators = {{"U1", upper, 40.0, 280.0},  {"U2", upper, 360.0, 280.0},
                     {"U3", upper, 200.0, 320.0}, {"L1", lower, 40.0, 40.0},
                     {"L2", lower, 360.0, 40.0},  {"L3", lower, 200.0, 0.0}};
  layout.key_points = {{"K1", upper, 0.0, 200.0},   {"K2", upper, 200.0, 200.0},
                       {"K3", upper, 400.0, 320.0}, {"K4", upper, 200.0, 280.0},
                       {"K5", lower, 0.0, 120.0},   {"K6", lower, 200.0, 120.0},
                       {"K7", lower, 400.0, 0.0},   {"K8", lower, 200.0, 40.0}};
  if (door_like) {
    layout.supports = {{"S1", lower, 40.0, 40.0},   {"S2", lower, 360.0, 40.0},
                       {"S3", lower, 200.0, 0.0},   {"S4", upper, 40.0, 280.0},
                       {"S5", upper, 360.0, 280.0}, {"S6", upper, 200.0, 320.0}};
    layout.final_support = FinalSupport::nominal_frame;
    layout.weld_tie = WeldTie::translation_and_rotation;
  } else {
    layout.final_support = FinalSupport::adjusted_locators;
    layout.weld_tie = WeldTie::translation;
  }
  return layout;
}

}  // namespace twincal::contact_test_layouts
