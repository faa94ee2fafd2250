#include "twincal/sheet_metal/sheet_metal_layout.hpp"

#include <functional>
#include <string>

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
