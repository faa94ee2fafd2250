// twincal_calculix_twin: the CalculiX assembly twin as an external twin (docs/calculix.md).
// Reads JSON-lines requests on stdin and answers one line each on stdout (docs/external.md):
//   → {"id": n, "assembly": {"upper": i, "lower": j}, "controls": [[u_1, …, u_d], …]}
//   → {"id": n, "assembly": {"parts": {"upper": [w…], "lower": [w…]}}, "controls": …}
//   ← {"id": n, "qualities": [q…]}   (null where CalculiX did not converge)
//   → … "deviations": true}          (the key points' deviations instead, `--describe`'s
//   ← {"id": n, "deviations": [[y_1, …, y_m] or null, …]}                    key_points = m)
//   ← {"id": n, "error": "…"}        (a request it refuses, a solver that cannot run)
// Diagnostics go to stderr. `--describe` prints the twin's locators, bounds and mesh and exits.

#include <charconv>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <iostream>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "twincal/calculix/calculix_twin.hpp"
#include "twincal/calculix/influence_coefficient_twin.hpp"
#include "twincal/external/child_groups.hpp"

namespace {

using twincal::Index;

constexpr std::string_view usage = R"(usage: twincal_calculix_twin [options]
  --layout body|lap-joint   the assembly (default body: 12 locators, 20 mm grid)
  --refinement N            elements per layout element edge (default 1)
  --seed S                  synthetic parts' seed (default 2023)
  --upper-parts N, --lower-parts N   synthetic parts per side (default 10 each)
  --no-contact              no sheet-to-sheet contact (still NLGEOM)
  --linear                  no contact, small displacements: a linear solve
  --influence               the linear model's influence coefficients: d + U + L linear solves
                            at start, then each Q without the solver (scanned parts: one solve)
  --linearization small-displacement|secant   with --influence: the linear solve's coefficients
                            (default), or secants of this twin's own solve (contact, large
                            displacements) around the box's centre: 2d + 1 + U + L solves
  --secant-step-fraction F  the secant's half step per locator, a fraction of its box width in
                            (0, 0.5] (default 0.25)
  --nominal-gap MM          clearance between the sheets at nominal (default 0.02)
  --gap-stiffness N/MM      penalty of a closed gap (default 1e4)
  --locator-bound MM        locator box half-width (default 1)
  --max-increments N        increments per nonlinear step (default 100)
  --ccx PATH                the CalculiX solver (default ccx)
  --scratch DIR             scratch root (default the system's temporary directory)
  --keep-files              keep each solve's deck, log and results
  --threads N               threads per CalculiX process (default 1)
  --timeout-s S             kill a CalculiX run after S seconds (default 600)
  --describe                print the twin's locators, bounds and mesh as JSON and exit
)";

struct Arguments {
  std::string layout = "body";
  std::uint64_t seed = 2023;
  Index upper_parts = 10;
  Index lower_parts = 10;
  bool describe = false;
  bool influence = false;
  twincal::InfluenceCoefficientOptions influence_options;
  twincal::CalculixOptions options;
};

[[noreturn]] void refuse(const std::string& message) {
  std::cerr << "twincal_calculix_twin: " << message << "\n" << usage;
  std::exit(2);
}

template <typename T>
T parse_number(std::string_view option, std::string_view text) {
  T value{};
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc{} || end != text.data() + text.size()) {
    refuse(fmt::format("{}: value is '{}'; rule: must be a number", option, text));
  }
  return value;
}

Arguments parse_arguments(int argc, char** argv) {
  Arguments arguments;
  std::map<std::string, int> seen;
  for (int i = 1; i < argc; ++i) {
    const std::string option = argv[i];
    if (++seen[option] > 1) refuse(fmt::format("{}: given twice; rule: at most once", option));
    const auto value = [&]() -> std::string_view {
      if (i + 1 >= argc) refuse(fmt::format("{}: value missing", option));
      return argv[++i];
    };
    twincal::CalculixOptions& o = arguments.options;
    if (option == "--layout") {
      arguments.layout = value();
    } else if (option == "--refinement") {
      o.refinement = parse_number<Index>(option, value());
    } else if (option == "--seed") {
      arguments.seed = parse_number<std::uint64_t>(option, value());
    } else if (option == "--upper-parts") {
      arguments.upper_parts = parse_number<Index>(option, value());
    } else if (option == "--lower-parts") {
      arguments.lower_parts = parse_number<Index>(option, value());
    } else if (option == "--no-contact") {
      o.contact = false;
    } else if (option == "--linear") {
      o.contact = false;
      o.geometric_nonlinearity = false;
    } else if (option == "--influence") {
      arguments.influence = true;
    } else if (option == "--linearization") {
      const std::string_view text = value();
      const std::optional<twincal::InfluenceLinearization> linearization =
          twincal::parse_influence_linearization(text);
      if (!linearization) {
        refuse(fmt::format("{}: value is '{}'; rule: small-displacement or secant", option, text));
      }
      arguments.influence_options.linearization = *linearization;
    } else if (option == "--secant-step-fraction") {
      arguments.influence_options.secant_step_fraction = parse_number<double>(option, value());
    } else if (option == "--nominal-gap") {
      o.nominal_gap = parse_number<double>(option, value());
    } else if (option == "--gap-stiffness") {
      o.gap_stiffness = parse_number<double>(option, value());
    } else if (option == "--locator-bound") {
      o.locator_bound = parse_number<double>(option, value());
    } else if (option == "--max-increments") {
      o.max_increments = parse_number<Index>(option, value());
    } else if (option == "--ccx") {
      o.executable = value();
    } else if (option == "--scratch") {
      o.scratch_root = std::string(value());
    } else if (option == "--keep-files") {
      o.keep_files = true;
    } else if (option == "--threads") {
      o.solver_threads = parse_number<Index>(option, value());
    } else if (option == "--timeout-s") {
      o.timeout = std::chrono::milliseconds(
          static_cast<std::int64_t>(1000.0 * parse_number<double>(option, value())));
    } else if (option == "--describe") {
      arguments.describe = true;
    } else if (option == "--help" || option == "-h") {
      std::cout << usage;
      std::exit(0);
    } else {
      refuse(fmt::format("unknown option '{}'", option));
    }
  }
  const bool linearization_given =
      seen.count("--linearization") + seen.count("--secant-step-fraction") > 0;
  if (linearization_given && !arguments.influence) {
    refuse(
        "--linearization and --secant-step-fraction: given without --influence; rule: they "
        "choose how the influence map is built");
  }
  if (const std::optional<std::string> problem = arguments.influence_options.validate()) {
    refuse(*problem);
  }
  return arguments;
}

twincal::SheetMetalLayout layout_named(const std::string& name) {
  if (name == "body") return twincal::SheetMetalLayout::body();
  if (name == "lap-joint") return twincal::SheetMetalLayout::lap_joint();
  refuse(
      fmt::format("--layout: value is '{}'; rule: body or lap-joint (the door's welds lock "
                  "rotations, which this twin does not model)",
                  name));
}

twincal::VectorX part_from_json(const nlohmann::json& values, const char* name, Index nodes) {
  if (!values.is_array() || static_cast<Index>(values.size()) != nodes) {
    throw twincal::InvalidArgumentError(
        name, fmt::format("assembly.parts.{}: {} values; rule: an array of {} normal deviations "
                          "(mm), one per node of the part's mesh, row by row (--describe)",
                          name, values.is_array() ? values.size() : 0, nodes));
  }
  twincal::VectorX part(nodes);
  for (Index i = 0; i < nodes; ++i) {
    const nlohmann::json& v = values[static_cast<std::size_t>(i)];
    if (!v.is_number()) {
      throw twincal::InvalidArgumentError(
          name, fmt::format("assembly.parts.{}[{}]: not a number", name, i));
    }
    part(i) = v.get<double>();
  }
  return part;
}

nlohmann::json answer(const twincal::CalculixTwin& twin,
                      const twincal::InfluenceCoefficientTwin* influence,
                      const nlohmann::json& request) {
  const nlohmann::json& assembly = request.at("assembly");
  const nlohmann::json& controls = request.at("controls");
  const Index d = twin.control_dimension();
  if (!controls.is_array() || controls.empty()) {
    throw twincal::InvalidArgumentError("controls", "controls: rule: a non-empty array");
  }
  twincal::MatrixX u(d, static_cast<Index>(controls.size()));
  for (std::size_t c = 0; c < controls.size(); ++c) {
    if (!controls[c].is_array() || static_cast<Index>(controls[c].size()) != d) {
      throw twincal::InvalidArgumentError(
          "controls", fmt::format("controls[{}]: rule: an array of {} numbers", c, d));
    }
    for (Index k = 0; k < d; ++k)
      u(k, static_cast<Index>(c)) = controls[c][static_cast<std::size_t>(k)].get<double>();
  }
  twincal::CalculixParts parts;
  std::optional<twincal::AssemblyId> id;
  if (assembly.contains("parts")) {
    const auto& model = twin.model();
    parts.upper = part_from_json(assembly.at("parts").at("upper"), "upper",
                                 model.mesh(twincal::SheetMetalPart::upper).node_count());
    parts.lower = part_from_json(assembly.at("parts").at("lower"), "lower",
                                 model.mesh(twincal::SheetMetalPart::lower).node_count());
  } else {
    id = twincal::AssemblyId{assembly.at("upper").get<Index>(), assembly.at("lower").get<Index>()};
  }
  const std::string label = id ? fmt::format("assembly {}", *id) : "a scanned assembly";
  // The nonlinear solve needs the listed assembly's parts; the influence model looks them up.
  if (id && influence == nullptr) parts = twin.parts(*id);
  if (request.value("deviations", false)) {
    twincal::MatrixX y(twin.key_point_count(), u.cols());
    if (influence != nullptr) {
      if (id) {
        influence->deviations_batch(*id, u, y);
      } else {
        influence->deviations_batch(parts, u, y);
      }
    } else {
      const twincal::CalculixBatchSummary summary = twin.key_deviations(parts, u, y, label);
      if (!summary.failed.empty()) std::cerr << summary.last_failure << "\n";
    }
    nlohmann::json deviations = nlohmann::json::array();
    for (Index c = 0; c < y.cols(); ++c) {
      deviations.push_back(y.col(c).allFinite() ? nlohmann::json(std::vector<double>(
                                                      y.col(c).begin(), y.col(c).end()))
                                                : nlohmann::json(nullptr));
    }
    return {{"id", request.at("id")}, {"deviations", std::move(deviations)}};
  }
  twincal::VectorX q(u.cols());
  if (influence != nullptr) {
    if (id) {
      influence->quality_batch(*id, u, q);
    } else {
      influence->quality_batch(parts, u, q);
    }
  } else {
    const twincal::CalculixBatchSummary summary = twin.evaluate(parts, u, q, label);
    if (!summary.failed.empty()) std::cerr << summary.last_failure << "\n";
  }
  nlohmann::json qualities = nlohmann::json::array();
  for (Index c = 0; c < q.size(); ++c) {
    qualities.push_back(std::isfinite(q(c)) ? nlohmann::json(q(c)) : nlohmann::json(nullptr));
  }
  return {{"id", request.at("id")}, {"qualities", std::move(qualities)}};
}

nlohmann::json describe(const twincal::CalculixTwin& twin, const std::string& layout) {
  const auto& model = twin.model();
  std::vector<double> lower(twin.lower_bounds().begin(), twin.lower_bounds().end());
  std::vector<double> upper(twin.upper_bounds().begin(), twin.upper_bounds().end());
  return {{"layout", layout},
          {"element_size", model.layout().element_size},
          {"locators", twin.locator_names()},
          {"lower_bounds", lower},
          {"upper_bounds", upper},
          {"key_points", model.key_point_count()},
          {"contact_pairs", model.contact_pairs().size()},
          {"upper_nodes", model.mesh(twincal::SheetMetalPart::upper).node_count()},
          {"lower_nodes", model.mesh(twincal::SheetMetalPart::lower).node_count()},
          {"deck_nodes", model.deck_node_count()},
          {"assemblies", twin.upper_part_count() * twin.lower_part_count()}};
}

}  // namespace

int main(int argc, char** argv) {
  twincal::child_groups::end_child_groups_on_termination();
  const Arguments arguments = parse_arguments(argc, argv);
  std::optional<twincal::CalculixTwin> twin;
  try {
    twin.emplace(twincal::CalculixTwin::generate(layout_named(arguments.layout), arguments.options,
                                                 arguments.seed, arguments.upper_parts,
                                                 arguments.lower_parts));
  } catch (const twincal::Error& error) {
    refuse(error.what());
  }
  if (arguments.describe) {
    std::cout << describe(*twin, arguments.layout).dump() << "\n";
    return 0;
  }
  std::optional<twincal::InfluenceCoefficientTwin> influence;
  if (arguments.influence) {
    try {
      const auto started = std::chrono::steady_clock::now();
      influence.emplace(*twin, arguments.influence_options);
      std::cerr << fmt::format(
          "twincal_calculix_twin: influence coefficients ({}) from {} CalculiX runs in {:.2f} s\n",
          twincal::to_string(arguments.influence_options.linearization), influence->solver_runs(),
          std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count());
    } catch (const twincal::Error& error) {
      std::cerr << "twincal_calculix_twin: " << error.what() << "\n";
      return 1;
    }
  }
  std::string line;
  while (std::getline(std::cin, line)) {
    nlohmann::json reply;
    nlohmann::json id = nullptr;
    try {
      const nlohmann::json request = nlohmann::json::parse(line);
      if (request.is_object() && request.contains("id")) id = request["id"];
      reply = answer(*twin, influence ? &*influence : nullptr, request);
    } catch (const std::exception& error) {
      std::cerr << "twincal_calculix_twin: " << error.what() << "\n";
      reply = {{"id", id}, {"error", error.what()}};
    }
    std::cout << reply.dump() << std::endl;  // flushed: a reply in a buffer is a timeout
  }
  return 0;
}
