#include "twincal/sheet_metal/contact_pairs.hpp"

#include <cmath>

#include <gtest/gtest.h>

#include "contact_test_layouts.hpp"
#include "twincal/core/error.hpp"

namespace twincal::contact_pairs_test {
namespace {

bool is_weld(const SheetMetalLayout& layout, double x, double y) {
  for (const Vector<2>& weld : layout.welds) {
    if (std::abs(weld(0) - x) < 1e-9 && std::abs(weld(1) - y) < 1e-9) return true;
  }
  return false;
}

void expect_facing_overlap_nodes(const SheetMetalLayout& layout,
                                 const std::vector<ContactPair>& pairs) {
  const PlateMesh upper = layout.mesh(SheetMetalPart::upper);
  const PlateMesh lower = layout.mesh(SheetMetalPart::lower);
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    const ContactPair& pair = pairs[k];
    EXPECT_EQ(upper.x(pair.upper_node), pair.x);
    EXPECT_EQ(upper.y(pair.upper_node), pair.y);
    EXPECT_EQ(lower.x(pair.lower_node), pair.x);
    EXPECT_EQ(lower.y(pair.lower_node), pair.y);
    EXPECT_FALSE(is_weld(layout, pair.x, pair.y));
    if (k > 0) {  // row by row
      const ContactPair& before = pairs[k - 1];
      EXPECT_TRUE(before.y < pair.y || (before.y == pair.y && before.x < pair.x));
    }
  }
}

TEST(ContactPairs, BodyFlangeHasEveryOverlapNodeButTheWelds) {
  const SheetMetalLayout layout = SheetMetalLayout::body();
  const std::vector<ContactPair> pairs = flange_contact_pairs(layout);
  // Overlap y ∈ [340, 400]: 4 rows of 41 nodes, less 19 welds.
  EXPECT_EQ(pairs.size(), 4U * 41U - 19U);
  expect_facing_overlap_nodes(layout, pairs);
}

TEST(ContactPairs, DoorFlangeHasEveryOverlapNodeButTheWelds) {
  const SheetMetalLayout layout = SheetMetalLayout::door();
  const std::vector<ContactPair> pairs = flange_contact_pairs(layout);
  EXPECT_EQ(pairs.size(), 4U * 46U - 21U);
  expect_facing_overlap_nodes(layout, pairs);
}

TEST(ContactPairs, SmallLayoutAndInvalidLayouts) {
  const SheetMetalLayout layout = contact_test_layouts::small_lap_joint(false);
  const std::vector<ContactPair> pairs = flange_contact_pairs(layout);
  EXPECT_EQ(pairs.size(), 3U * 11U - 5U);
  expect_facing_overlap_nodes(layout, pairs);
  SheetMetalLayout broken = layout;
  broken.element_size = -1.0;
  EXPECT_THROW((void)flange_contact_pairs(broken), InvalidArgumentError);
}

}  // namespace
}  // namespace twincal::contact_pairs_test
