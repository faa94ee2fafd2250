#include "twincal/sheet_metal/sheet_metal_layout.hpp"

#include <algorithm>
#include <array>
#include <functional>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "twincal/core/error.hpp"

namespace twincal::sheet_metal_layout_test {
namespace {

using ::testing::HasSubstr;

// The validation message after `change` is applied to the body layout ("" when valid).
std::string problem_after(const std::function<void(SheetMetalLayout&)>& change) {
  SheetMetalLayout layout = SheetMetalLayout::body();
  change(layout);
  return layout.validate().value_or("");
}

TEST(SheetMetalLayout, CasesAreValidWithTheirCounts) {
  const SheetMetalLayout body = SheetMetalLayout::body();
  const SheetMetalLayout door = SheetMetalLayout::door();
  EXPECT_EQ(body.validate(), std::nullopt);
  EXPECT_EQ(door.validate(), std::nullopt);
  EXPECT_EQ(body.locators.size(), 12U);
  EXPECT_EQ(door.locators.size(), 19U);
  EXPECT_EQ(body.final_support, FinalSupport::adjusted_locators);
  EXPECT_EQ(door.final_support, FinalSupport::nominal_frame);
  EXPECT_EQ(door.weld_tie, WeldTie::translation_and_rotation);
  const PlateMesh mesh = body.mesh(SheetMetalPart::upper);
  EXPECT_EQ(mesh.elements_x(), 40);
  EXPECT_EQ(mesh.elements_y(), 20);
  EXPECT_DOUBLE_EQ(mesh.origin_y(), 340.0);
  // Every weld is a node of both meshes.
  for (const Vector<2>& w : body.welds) {
    EXPECT_TRUE(body.mesh(SheetMetalPart::upper).find_node(w(0), w(1)).has_value());
    EXPECT_TRUE(body.mesh(SheetMetalPart::lower).find_node(w(0), w(1)).has_value());
  }
}

TEST(SheetMetalLayout, ValidateNamesTheBrokenRule) {
  EXPECT_THAT(problem_after([](SheetMetalLayout& l) { l.element_size = 0.0; }),
              HasSubstr("element_size: value is 0; rule: must be finite and > 0"));
  EXPECT_THAT(problem_after([](SheetMetalLayout& l) { l.upper.width = 810.0; }),
              HasSubstr("whole multiples of element_size"));
  EXPECT_THAT(problem_after([](SheetMetalLayout& l) { l.upper.y0 = 345.0; }),
              HasSubstr("one shared grid"));
  EXPECT_THAT(problem_after([](SheetMetalLayout& l) { l.locators[1].name = "U1"; }),
              HasSubstr("name 'U1' repeats"));
  EXPECT_THAT(problem_after([](SheetMetalLayout& l) { l.locators.resize(8); }),
              HasSubstr("6 upper and 2 lower; rule: each part needs >= 3"));
  EXPECT_THAT(problem_after([](SheetMetalLayout& l) { l.welds.clear(); }),
              HasSubstr("welds: value is empty"));
  EXPECT_THAT(problem_after([](SheetMetalLayout& l) { l.welds[0](1) = 300.0; }),
              HasSubstr("must lie in the overlap"));
  EXPECT_THAT(problem_after([](SheetMetalLayout& l) {
                l.locators[0] = {"U1", SheetMetalPart::upper, 40.0, 360.0};
              }),
              HasSubstr("U1 sits on the weld"));
  EXPECT_THAT(problem_after([](SheetMetalLayout& l) { l.key_points.clear(); }),
              HasSubstr("key_points: value is empty"));
  EXPECT_THAT(problem_after([](SheetMetalLayout& l) { l.key_points[0].y = 100.0; }),
              HasSubstr("must lie on its (upper) part"));
  EXPECT_THAT(
      problem_after([](SheetMetalLayout& l) { l.final_support = FinalSupport::nominal_frame; }),
      HasSubstr("supports: value is 0 points; rule: a nominal frame needs >= 3"));
  EXPECT_EQ(problem_after([](SheetMetalLayout&) {}), "");
}

// supports_at puts S1, S2, … at the named locators' nominal positions, in the order named, and
// refuses a name the layout lacks, listing the ones it has.
TEST(SheetMetalLayout, SupportsAtNamedLocatorsAndRefusesAnUnknownName) {
  const SheetMetalLayout layout = SheetMetalLayout::lap_joint();
  const std::vector<LayoutPoint> supports = layout.supports_at({"U2", "L1"});
  ASSERT_EQ(supports.size(), 2U);
  const std::array<std::string, 2> named{"U2", "L1"};
  for (std::size_t i = 0; i < supports.size(); ++i) {
    const auto locator = std::find_if(layout.locators.begin(), layout.locators.end(),
                                      [&](const LayoutPoint& p) { return p.name == named[i]; });
    ASSERT_NE(locator, layout.locators.end());
    EXPECT_EQ(supports[i].name, "S" + std::to_string(i + 1));
    EXPECT_EQ(supports[i].part, locator->part);
    EXPECT_EQ(supports[i].x, locator->x);
    EXPECT_EQ(supports[i].y, locator->y);
  }
  try {
    (void)layout.supports_at({"L1", "Q9"});
    FAIL() << "Q9 was accepted";
  } catch (const InvalidArgumentError& error) {
    EXPECT_THAT(error.what(), HasSubstr("locator_names: value is 'Q9'; rule: must be one of the "
                                        "layout's locators [U1, U2, U3, L1, L2, L3]"));
  }
}

TEST(SheetMetalLayout, JsonCarriesTheLayout) {
  const SheetMetalLayout door = SheetMetalLayout::door();
  const nlohmann::json json = nlohmann::json::parse(door.to_json());
  EXPECT_EQ(json["name"], "door");
  EXPECT_EQ(json["locators"].size(), 19U);
  EXPECT_EQ(json["welds"].size(), door.welds.size());
  EXPECT_EQ(json["key_points"].size(), door.key_points.size());
  EXPECT_EQ(json["supports"].size(), door.supports.size());
  EXPECT_EQ(json["locators"][0]["name"], "U1");
  EXPECT_EQ(json["locators"][18]["part"], "lower");
  EXPECT_EQ(json["final_support"], "nominal_frame");
  EXPECT_EQ(json["weld_tie"], "translation_and_rotation");
  EXPECT_DOUBLE_EQ(json["upper"]["y0"].get<double>(), door.upper.y0);
}

}  // namespace
}  // namespace twincal::sheet_metal_layout_test
