#include "twincal/sheet_metal/sheet_metal_layout.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <string>
#include <string_view>
#include <utility>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "twincal/core/error.hpp"
#include "twincal/core/options.hpp"

namespace twincal {

namespace {

constexpr SheetMetalPart upper_part = SheetMetalPart::upper;
constexpr SheetMetalPart lower_part = SheetMetalPart::lower;

// Whether `value` is a whole multiple of `step` (within 1e-9 relative).
bool whole_multiple(double value, double step) {
  const double ratio = value / step;
  return std::abs(ratio - std::round(ratio)) < 1e-9 * std::max(1.0, std::abs(ratio));
}

bool inside(const PartOutline& o, double x, double y) {
  constexpr double tolerance = 1e-6;
  return x >= o.x0 - tolerance && x <= o.x0 + o.width + tolerance && y >= o.y0 - tolerance &&
         y <= o.y0 + o.height + tolerance;
}

const char* part_name(SheetMetalPart part) {
  return part == SheetMetalPart::upper ? "upper" : "lower";
}

// Spot welds every `pitch` mm along x, alternating between the rows y_a and y_b (a staggered
// double row, so the joint is not a hinge even with translation-only welds).
std::vector<Vector<2>> staggered_welds(double x_first, double x_last, double pitch, double y_a,
                                       double y_b) {
  std::vector<Vector<2>> welds;
  const auto count = static_cast<int>(std::floor((x_last - x_first) / pitch + 1e-9)) + 1;
  for (int k = 0; k < count; ++k) {
    welds.emplace_back(x_first + k * pitch, k % 2 == 0 ? y_a : y_b);
  }
  return welds;
}

// The points (x, y) for y in ys, x in xs, numbered on from the points of the list whose name
// has the prefix (key points K1 to K18 over both parts; locators U1–U6, then L1–L6).
void add_grid(std::vector<LayoutPoint>& points, const std::string& prefix, SheetMetalPart part,
              const std::vector<double>& xs, const std::vector<double>& ys) {
  auto number = std::count_if(points.begin(), points.end(), [&](const LayoutPoint& point) {
    return point.name.starts_with(prefix);
  });
  for (const double y : ys) {
    for (const double x : xs) {
      points.push_back({fmt::format("{}{}", prefix, ++number), part, x, y});
    }
  }
}

// The body's and the door's frame: two width × height parts, the upper lapping the lower's top
// 60 mm (the flange), on 20 mm elements, with a staggered double row of welds every 40 mm along
// the flange, 40 mm in from either end.
SheetMetalLayout lap_flange_layout(std::string name, double width, double height,
                                   FinalSupport final_support, WeldTie weld_tie) {
  SheetMetalLayout layout;
  layout.name = std::move(name);
  layout.element_size = 20.0;
  layout.lower = {0.0, 0.0, width, height};
  layout.upper = {0.0, height - 60.0, width, height};
  layout.welds = staggered_welds(40.0, width - 40.0, 40.0, height - 40.0, height - 20.0);
  layout.final_support = final_support;
  layout.weld_tie = weld_tie;
  return layout;
}

}  // namespace

std::vector<Index> tied_components(WeldTie tie) {
  if (tie == WeldTie::translation) return {0};
  return {0, 1, 2};
}

SheetMetalLayout SheetMetalLayout::lap_joint() {
  constexpr SheetMetalPart upper = SheetMetalPart::upper;
  constexpr SheetMetalPart lower = SheetMetalPart::lower;
  SheetMetalLayout layout;
  layout.name = "lap-joint";
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
  layout.final_support = FinalSupport::adjusted_locators;
  layout.weld_tie = WeldTie::translation;
  return layout;
}

SheetMetalLayout SheetMetalLayout::body() {
  SheetMetalLayout layout = lap_flange_layout("body", 800.0, 400.0, FinalSupport::adjusted_locators,
                                              WeldTie::translation);
  add_grid(layout.locators, "U", upper_part, {100.0, 400.0, 700.0}, {440.0, 680.0});
  add_grid(layout.locators, "L", lower_part, {100.0, 400.0, 700.0}, {60.0, 300.0});
  // 3 × 3 key points per part: edges, middle and the flange, m = 18.
  add_grid(layout.key_points, "K", upper_part, {20.0, 400.0, 780.0}, {400.0, 560.0, 740.0});
  add_grid(layout.key_points, "K", lower_part, {20.0, 400.0, 780.0}, {0.0, 180.0, 340.0});
  return layout;
}

SheetMetalLayout SheetMetalLayout::door() {
  SheetMetalLayout layout = lap_flange_layout("door", 900.0, 500.0, FinalSupport::nominal_frame,
                                              WeldTie::translation_and_rotation);
  add_grid(layout.locators, "U", upper_part, {100.0, 280.0, 460.0, 640.0, 800.0}, {620.0, 860.0});
  add_grid(layout.locators, "L", lower_part, {100.0, 460.0, 800.0}, {60.0, 200.0, 340.0});
  add_grid(layout.key_points, "K", upper_part, {20.0, 240.0, 460.0, 680.0, 880.0},
           {520.0, 700.0, 920.0});
  add_grid(layout.key_points, "K", lower_part, {20.0, 240.0, 460.0, 680.0, 880.0},
           {20.0, 240.0, 420.0});
  // A nominal N-2-1 frame with three pins under each part.
  layout.supports = layout.supports_at({"L1", "L3", "L8", "U6", "U10", "U3"});
  return layout;
}

std::vector<LayoutPoint> SheetMetalLayout::supports_at(
    const std::vector<std::string>& locator_names) const {
  std::vector<LayoutPoint> out;
  for (const std::string& wanted : locator_names) {
    const auto locator = std::find_if(locators.begin(), locators.end(),
                                      [&](const LayoutPoint& p) { return p.name == wanted; });
    if (locator == locators.end()) {
      std::vector<std::string_view> names;
      for (const LayoutPoint& p : locators) names.push_back(p.name);
      throw InvalidArgumentError(
          "locator_names",
          fmt::format(
              "locator_names: value is '{}'; rule: must be one of the layout's locators [{}]",
              wanted, fmt::join(names, ", ")));
    }
    out.push_back({fmt::format("S{}", out.size() + 1), locator->part, locator->x, locator->y});
  }
  return out;
}

PlateMesh SheetMetalLayout::mesh(SheetMetalPart part) const {
  const PartOutline& o = part == SheetMetalPart::upper ? upper : lower;
  if (!whole_multiple(o.width, element_size) || !whole_multiple(o.height, element_size)) {
    throw InvalidArgumentError(
        "layout", fmt::format("layout: {} part is {} x {} mm; rule: must be whole multiples of "
                              "element_size {} mm",
                              part_name(part), o.width, o.height, element_size));
  }
  const auto nx = static_cast<Index>(std::round(o.width / element_size));
  const auto ny = static_cast<Index>(std::round(o.height / element_size));
  return {nx, ny, element_size, element_size, o.x0, o.y0};
}

std::optional<std::string> SheetMetalLayout::validate() const {
  if (auto problem = rule::positive_finite("element_size", element_size)) return problem;
  for (const SheetMetalPart part : {upper_part, lower_part}) {
    const PartOutline& o = part == upper_part ? upper : lower;
    if (!(o.width > 0.0) || !(o.height > 0.0) || !whole_multiple(o.width, element_size) ||
        !whole_multiple(o.height, element_size)) {
      return fmt::format(
          "{}: value is {} x {} mm; rule: must be > 0 and whole multiples of "
          "element_size {} mm",
          part_name(part), o.width, o.height, element_size);
    }
  }
  if (!whole_multiple(upper.x0 - lower.x0, element_size) ||
      !whole_multiple(upper.y0 - lower.y0, element_size)) {
    return fmt::format(
        "upper: origin offset ({}, {}) mm from lower; rule: must be whole "
        "multiples of element_size (one shared grid, so welds are nodes of both)",
        upper.x0 - lower.x0, upper.y0 - lower.y0);
  }
  std::set<std::string> names;
  int upper_count = 0;
  for (const LayoutPoint& p : locators) {
    if (!names.insert(p.name).second) {
      return fmt::format("locators: name '{}' repeats; rule: names must be unique", p.name);
    }
    upper_count += p.part == upper_part ? 1 : 0;
  }
  const auto lower_count = static_cast<int>(locators.size()) - upper_count;
  if (upper_count < 3 || lower_count < 3) {
    return fmt::format("locators: {} upper and {} lower; rule: each part needs >= 3", upper_count,
                       lower_count);
  }
  if (welds.empty()) return "welds: value is empty; rule: needs at least one weld";
  for (std::size_t j = 0; j < welds.size(); ++j) {
    if (!inside(upper, welds[j](0), welds[j](1)) || !inside(lower, welds[j](0), welds[j](1))) {
      return fmt::format(
          "welds: weld {} at ({}, {}) mm; rule: must lie in the overlap of both "
          "parts",
          j, welds[j](0), welds[j](1));
    }
  }
  for (const LayoutPoint& p : locators) {
    for (const Vector<2>& w : welds) {
      if (std::abs(p.x - w(0)) < 1e-6 && std::abs(p.y - w(1)) < 1e-6) {
        return fmt::format(
            "locators: {} sits on the weld at ({}, {}) mm; rule: a locator and a "
            "weld cannot share a node (the gun and the clamp would fight)",
            p.name, w(0), w(1));
      }
    }
  }
  if (key_points.empty()) return "key_points: value is empty; rule: needs at least one key point";
  for (const auto* list : {&locators, &key_points, &supports}) {
    for (const LayoutPoint& p : *list) {
      if (!inside(p.part == upper_part ? upper : lower, p.x, p.y)) {
        return fmt::format("point {} at ({}, {}) mm; rule: must lie on its ({}) part", p.name, p.x,
                           p.y, part_name(p.part));
      }
    }
  }
  if (final_support == FinalSupport::nominal_frame && supports.size() < 3) {
    return fmt::format("supports: value is {} points; rule: a nominal frame needs >= 3",
                       supports.size());
  }
  return std::nullopt;
}

std::string SheetMetalLayout::to_json() const {
  using nlohmann::json;
  const auto outline = [](const PartOutline& o) {
    return json{{"x0", o.x0}, {"y0", o.y0}, {"width", o.width}, {"height", o.height}};
  };
  const auto points = [](const std::vector<LayoutPoint>& list) {
    json array = json::array();
    for (const LayoutPoint& p : list) {
      array.push_back({{"name", p.name}, {"part", part_name(p.part)}, {"x", p.x}, {"y", p.y}});
    }
    return array;
  };
  json weld_array = json::array();
  for (const Vector<2>& w : welds) weld_array.push_back({{"x", w(0)}, {"y", w(1)}});
  const json document{
      {"name", name},
      {"element_size", element_size},
      {"upper", outline(upper)},
      {"lower", outline(lower)},
      {"locators", points(locators)},
      {"welds", weld_array},
      {"key_points", points(key_points)},
      {"supports", points(supports)},
      {"final_support",
       final_support == FinalSupport::adjusted_locators ? "adjusted_locators" : "nominal_frame"},
      {"weld_tie", weld_tie == WeldTie::translation ? "translation" : "translation_and_rotation"}};
  return document.dump(2);
}

}  // namespace twincal
