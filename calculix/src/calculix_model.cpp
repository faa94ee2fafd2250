#include "twincal/calculix/calculix_model.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <string>
#include <utility>

#include <fmt/format.h>

#include "twincal/calculix/calculix_error.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/validate.hpp"

namespace twincal {
namespace {

constexpr SheetMetalPart upper_part = SheetMetalPart::upper;
constexpr SheetMetalPart lower_part = SheetMetalPart::lower;

SheetMetalLayout refined(SheetMetalLayout layout, const CalculixOptions& options) {
  if (auto problem = options.validate()) {
    throw InvalidArgumentError("options", "calculix options: " + *problem);
  }
  if (auto problem = layout.validate()) {
    throw InvalidArgumentError("layout", "calculix layout: " + *problem);
  }
  if (layout.weld_tie != WeldTie::translation) {
    throw InvalidArgumentError(
        "layout.weld_tie",
        fmt::format("layout.weld_tie: value is translation_and_rotation (layout '{}'); rule: the "
                    "CalculiX twin's nuggets tie the normal displacement only (translation)",
                    layout.name));
  }
  layout.element_size /= static_cast<double>(options.refinement);
  return layout;
}

// CalculiX reads a number field of at most 20 characters: the shortest representation that
// round-trips, else the most significant digits that fit (17 → 15 digits lose < 1e-14 of it).
std::string ccx_number(double value) {
  std::string text = fmt::format("{}", value);
  for (int digits = 16; text.size() > 20 && digits > 0; --digits) {
    text = fmt::format("{:.{}g}", value, digits);
  }
  return text;
}

template <typename... Args>
void append(std::string& out, fmt::format_string<Args...> format, Args&&... args) {
  fmt::format_to(std::back_inserter(out), format, std::forward<Args>(args)...);
}

}  // namespace

CalculixModel::CalculixModel(SheetMetalLayout layout, CalculixOptions options)
    : layout_(refined(std::move(layout), options)),
      options_(std::move(options)),
      upper_mesh_(layout_.mesh(upper_part)),
      lower_mesh_(layout_.mesh(lower_part)),
      pairs_(options_.contact ? flange_contact_pairs(layout_) : std::vector<ContactPair>{}) {
  const auto node_of = [&](const LayoutPoint& point) {
    return PointNode{point.part, mesh(point.part).node_at(point.x, point.y, point.name)};
  };
  for (const LayoutPoint& point : layout_.locators) locator_nodes_.push_back(node_of(point));
  for (const LayoutPoint& point : layout_.key_points) key_nodes_.push_back(node_of(point));
  for (const LayoutPoint& point : layout_.supports) support_nodes_.push_back(node_of(point));
  for (const Vector<2>& weld : layout_.welds) {
    upper_weld_nodes_.push_back(upper_mesh_.node_at(weld.x(), weld.y(), "weld"));
    lower_weld_nodes_.push_back(lower_mesh_.node_at(weld.x(), weld.y(), "weld"));
  }
  // In-plane 2-1 pinning per part at its first two locators: the locators hold the normal
  // direction only, and without the pins each sheet could slide and spin in its plane.
  const auto pins = [&](SheetMetalPart part) {
    std::vector<const LayoutPoint*> points;
    for (const LayoutPoint& point : layout_.locators) {
      if (point.part == part) points.push_back(&point);
    }
    if (points.size() < 2) {
      throw InvalidArgumentError(
          "layout.locators",
          fmt::format("layout.locators: the {} part has {}; rule: at least 2 per part (the "
                      "in-plane pins)",
                      part == upper_part ? "upper" : "lower", points.size()));
    }
    const LayoutPoint& a = *points[0];
    const LayoutPoint& b = *points[1];
    return InPlanePins{mesh(part).node_at(a.x, a.y, a.name), mesh(part).node_at(b.x, b.y, b.name),
                       std::abs(b.x - a.x) >= std::abs(b.y - a.y) ? 2 : 1};
  };
  lower_pins_ = pins(lower_part);
  upper_pins_ = pins(upper_part);
}

Index CalculixModel::deck_node_count() const noexcept {
  return 2 * (lower_mesh_.node_count() + upper_mesh_.node_count()) +
         static_cast<Index>(layout_.welds.size());
}

Index CalculixModel::deck_node(SheetMetalPart part, Index node, Index face) const noexcept {
  // Lower sheet: bottom face, then top face; then the upper sheet's two faces. 1-based.
  const Index lower_nodes = lower_mesh_.node_count();
  if (part == lower_part) return 1 + face * lower_nodes + node;
  return 1 + 2 * lower_nodes + face * upper_mesh_.node_count() + node;
}

Index CalculixModel::weld_aux_node(std::size_t weld) const noexcept {
  // After both sheets' nodes, one per weld.
  return 1 + 2 * (lower_mesh_.node_count() + upper_mesh_.node_count()) + static_cast<Index>(weld);
}

double CalculixModel::free_shape(const CalculixParts& parts, SheetMetalPart part,
                                 Index node) const noexcept {
  return part == upper_part ? parts.upper(node) : parts.lower(node);
}

void CalculixModel::require_parts(const CalculixParts& parts) const {
  const auto check = [](const char* name, const VectorX& part, Index nodes) {
    require_dimension(name, part.size(), nodes);
    for (Index i = 0; i < part.size(); ++i) {
      if (!std::isfinite(part(i))) {
        throw NonFiniteError(
            name, fmt::format("{}: entry {} is {}; rule: must be finite (mm)", name, i, part(i)));
      }
    }
  };
  check("parts.upper", parts.upper, upper_mesh_.node_count());
  check("parts.lower", parts.lower, lower_mesh_.node_count());
}

void CalculixModel::require_controls(const Eigen::Ref<const MatrixX>& controls) const {
  if (controls.cols() == 0) {
    throw InvalidArgumentError("controls", "controls: batch is empty; rule: at least one column");
  }
  require_dimension("controls (rows)", controls.rows(), control_dimension());
  for (Index c = 0; c < controls.cols(); ++c) {
    for (Index k = 0; k < controls.rows(); ++k) {
      if (!std::isfinite(controls(k, c))) {
        throw NonFiniteError("controls", fmt::format("controls: entry ({}, {}) is {}; rule: "
                                                     "must be finite (mm)",
                                                     k, c, controls(k, c)));
      }
    }
  }
}

void CalculixModel::write_model(std::string& out, const CalculixParts& parts) const {
  const double t = options_.section.thickness;
  append(out,
         "** twincal CalculiX assembly twin: layout '{}', {} mm elements, contact {}, NLGEOM {}\n",
         layout_.name, layout_.element_size, options_.contact ? "on" : "off",
         options_.geometric_nonlinearity ? "on" : "off");
  out += "*NODE, NSET=NALL\n";
  for (const SheetMetalPart part : {lower_part, upper_part}) {
    const PlateMesh& m = mesh(part);
    const double mid = part == upper_part ? t + options_.nominal_gap : 0.0;
    for (Index face = 0; face < 2; ++face) {
      const double offset = face == 0 ? -0.5 * t : 0.5 * t;
      for (Index node = 0; node < m.node_count(); ++node) {
        append(out, "{}, {}, {}, {}\n", deck_node(part, node, face), ccx_number(m.x(node)),
               ccx_number(m.y(node)), ccx_number(mid + free_shape(parts, part, node) + offset));
      }
    }
  }
  for (std::size_t w = 0; w < layout_.welds.size(); ++w) {
    append(out, "{}, {}, {}, 0\n", weld_aux_node(w), ccx_number(layout_.welds[w].x()),
           ccx_number(layout_.welds[w].y()));
  }
  Index element = 0;
  for (const SheetMetalPart part : {lower_part, upper_part}) {
    const PlateMesh& m = mesh(part);
    append(out, "*ELEMENT, TYPE=C3D8I, ELSET={}\n", part == upper_part ? "UPPER" : "LOWER");
    for (Index j = 0; j < m.elements_y(); ++j) {
      for (Index i = 0; i < m.elements_x(); ++i) {
        const Eigen::Matrix<Index, 4, 1> corners = m.element_nodes(i, j);
        append(out, "{}", ++element);
        for (Index face = 0; face < 2; ++face) {
          for (Index c = 0; c < 4; ++c) append(out, ", {}", deck_node(part, corners(c), face));
        }
        out += '\n';
      }
    }
  }
  // The nugget: e_z,U − e_z,L − e_z,aux = 0 through the thickness (both face pairs), the
  // upper nodes dependent; the auxiliary node carries the gap the gun closes.
  out += "*EQUATION\n";
  for (std::size_t w = 0; w < layout_.welds.size(); ++w) {
    const Index aux = weld_aux_node(w);
    for (Index face = 0; face < 2; ++face) {
      append(out, "3\n{}, 3, 1., {}, 3, -1., {}, 3, -1.\n",
             deck_node(upper_part, upper_weld_nodes_[w], face),
             deck_node(lower_part, lower_weld_nodes_[w], 1 - face), aux);
    }
  }
  for (std::size_t k = 0; k < pairs_.size(); ++k) {
    const ContactPair& pair = pairs_[k];
    const double clearance =
        options_.nominal_gap + parts.upper(pair.upper_node) - parts.lower(pair.lower_node);
    append(out, "*ELEMENT, TYPE=GAPUNI, ELSET=GAP{}\n{}, {}, {}\n", k, ++element,
           deck_node(lower_part, pair.lower_node, 1), deck_node(upper_part, pair.upper_node, 0));
    append(out, "*GAP, ELSET=GAP{}\n{}, 0., 0., 1., , {}, {}\n", k, ccx_number(clearance),
           ccx_number(options_.gap_stiffness), ccx_number(options_.open_gap_force));
  }
  append(out, "*MATERIAL, NAME=STEEL\n*ELASTIC\n{}, {}\n",
         ccx_number(options_.section.young_modulus), ccx_number(options_.section.poisson_ratio));
  out += "*SOLID SECTION, ELSET=LOWER, MATERIAL=STEEL\n";
  out += "*SOLID SECTION, ELSET=UPPER, MATERIAL=STEEL\n";
  out += "*NSET, NSET=KEYS\n";
  for (const PointNode& key : key_nodes_) {
    append(out, "{}\n{}\n", deck_node(key.part, key.node, 0), deck_node(key.part, key.node, 1));
  }
}

void CalculixModel::write_fixture(std::string& out, const CalculixParts& parts,
                                  const Eigen::Ref<const VectorX>& control, bool release) const {
  out += "*BOUNDARY, OP=NEW\n";
  const auto hold = [&](const PointNode& point, double total) {
    const double e = total - free_shape(parts, point.part, point.node);
    for (Index face = 0; face < 2; ++face) {
      append(out, "{}, 3, 3, {}\n", deck_node(point.part, point.node, face), ccx_number(e));
    }
  };
  const bool on_locators = !release || layout_.final_support == FinalSupport::adjusted_locators;
  if (on_locators) {
    for (std::size_t k = 0; k < locator_nodes_.size(); ++k) {
      hold(locator_nodes_[k], control(static_cast<Index>(k)));
    }
  } else {
    for (const PointNode& support : support_nodes_) hold(support, 0.0);
  }
  for (const auto& [part, pins] :
       {std::pair{lower_part, lower_pins_}, std::pair{upper_part, upper_pins_}}) {
    append(out, "{}, 1, 2\n{}, {}, {}\n", deck_node(part, pins.both, 0),
           deck_node(part, pins.one, 0), pins.direction, pins.direction);
  }
  for (std::size_t w = 0; w < layout_.welds.size(); ++w) {
    append(out, "{}, 3, 3, {}\n", weld_aux_node(w),
           ccx_number(parts.lower(lower_weld_nodes_[w]) - parts.upper(upper_weld_nodes_[w])));
  }
}

CalculixParts CalculixModel::placed(const CalculixParts& parts) const {
  double lift = 0.0;
  for (const ContactPair& pair : pairs_) {
    lift = std::max(lift, parts.lower(pair.lower_node) - parts.upper(pair.upper_node));
  }
  for (std::size_t w = 0; w < upper_weld_nodes_.size(); ++w) {
    lift = std::max(lift, parts.lower(lower_weld_nodes_[w]) - parts.upper(upper_weld_nodes_[w]));
  }
  CalculixParts lifted = parts;
  lifted.upper.array() += lift;
  return lifted;
}

std::string CalculixModel::deck(const CalculixParts& free_parts,
                                const Eigen::Ref<const MatrixX>& controls) const {
  require_parts(free_parts);
  require_controls(controls);
  const CalculixParts parts = placed(free_parts);
  std::string out;
  out.reserve(static_cast<std::size_t>(160 * deck_node_count()));
  write_model(out, parts);
  const std::string step =
      options_.geometric_nonlinearity
          ? fmt::format(
                "*STEP, NLGEOM, INC={}\n*STATIC\n1., 1., 1e-05, 1.\n"
                "*CONTROLS, PARAMETERS=TIME INCREMENTATION\n"
                "4, 8, 9, {}, 10, 4, , {}\n",
                options_.max_increments, options_.max_iterations, options_.max_cutbacks)
          : std::string("*STEP\n*STATIC\n");
  for (Index c = 0; c < controls.cols(); ++c) {
    append(out, "** column {}: clamp and weld\n{}", c, step);
    write_fixture(out, parts, controls.col(c), false);
    out += "*END STEP\n";
    append(out, "** column {}: release\n{}", c, step);
    write_fixture(out, parts, controls.col(c), true);
    out += "*NODE PRINT, NSET=KEYS\nU\n*END STEP\n";
  }
  return out;
}

VectorX CalculixModel::key_deviations(const CalculixParts& free_parts,
                                      const NodePrint& print) const {
  const CalculixParts parts = placed(free_parts);
  VectorX y(key_point_count());
  for (Index i = 0; i < key_point_count(); ++i) {
    const PointNode& key = key_nodes_[static_cast<std::size_t>(i)];
    double sum = 0.0;
    for (Index face = 0; face < 2; ++face) {
      const Index wanted = deck_node(key.part, key.node, face);
      std::size_t row = 0;
      while (row < print.nodes.size() && print.nodes[row] != wanted) ++row;
      if (row == print.nodes.size()) {
        throw CalculixError(
            CalculixFailure::unreadable_results,
            fmt::format("calculix results: the print at time {} lacks node {} "
                        "(key point {}); rule: every key-point node is printed",
                        print.time, wanted, layout_.key_points[static_cast<std::size_t>(i)].name),
            "");
      }
      sum += print.displacements[row](2);
    }
    y(i) = free_shape(parts, key.part, key.node) + 0.5 * sum;
  }
  return y;
}

}  // namespace twincal
