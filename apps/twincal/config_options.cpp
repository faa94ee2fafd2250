#include "config_options.hpp"

#include <array>
#include <utility>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "twincal/core/error.hpp"
#include "twincal/core/named_enum.hpp"
#include "twincal/experiments/config_file.hpp"
#include "twincal/experiments/experiment_choices.hpp"

namespace twincal::cli {
namespace {

using nlohmann::json;

// The spellings of a named enum as the help lists them: "a | b | c".
template <NamedEnum Enum>
std::string choices() {
  std::vector<std::string_view> names;
  for (const auto& entry : name_table(std::type_identity<Enum>{})) names.push_back(entry.name);
  return fmt::format("{}", fmt::join(names, " | "));
}

std::vector<ControllerSpec> parse_controllers(const std::string& list) {
  if (list == "paper") return ControllerSpec::paper();
  std::vector<ControllerSpec> specs;
  for (const std::string_view item : split_commas(list)) {
    specs.push_back(ControllerSpec::parse(item));
  }
  return specs;
}

// Help texts take the default config; a row whose help states no default ignores it.
using Defaults = const ExperimentConfig&;

constexpr auto options = std::to_array<ConfigOption>({
    {"runs", "N",
     [](Defaults d) { return fmt::format("runs per controller (default {})", d.runs); },
     [](Arguments& a, ExperimentConfig& c) {
       if (const auto v = a.integer("runs")) c.runs = *v;
     }},
    {"assemblies", "N",
     [](Defaults d) {
       return fmt::format("assemblies per episode (default {}: all, in a seeded random order)",
                          d.assemblies);
     },
     [](Arguments& a, ExperimentConfig& c) {
       if (const auto v = a.integer("assemblies")) c.assemblies = *v;
     }},
    {"seed", "S",
     [](Defaults d) { return fmt::format("master seed of the runs (default {})", d.seed); },
     [](Arguments& a, ExperimentConfig& c) {
       if (const auto v = a.seed("seed")) c.seed = *v;
     }},
    {"twin-seed", "S",
     [](Defaults d) { return fmt::format("seed of the twin (default {})", d.twin_seed); },
     [](Arguments& a, ExperimentConfig& c) {
       if (const auto v = a.seed("twin-seed")) c.twin_seed = *v;
     }},
    {"dimension", "D",
     [](Defaults d) {
       return fmt::format("locators of the analytic twin (default {})", d.analytic_dimension);
     },
     [](Arguments& a, ExperimentConfig& c) {
       if (const auto v = a.integer("dimension")) c.analytic_dimension = *v;
     }},
    {"nonlinearity", "K",
     [](Defaults d) {
       return fmt::format("the analytic twin's: {} (none: RMS-quadratic; default {})",
                          choices<Nonlinearity>(), to_string(d.nonlinearity));
     },
     [](Arguments& a, ExperimentConfig& c) {
       if (const auto v = a.text("nonlinearity")) {
         c.nonlinearity = parse_enum<Nonlinearity>(*v, "--nonlinearity");
       }
     }},
    {"strength", "S",
     [](Defaults d) {
       return fmt::format("the nonlinearity's strength (default {}; contact in [0, 1])",
                          d.strength);
     },
     [](Arguments& a, ExperimentConfig& c) {
       if (const auto v = a.real("strength")) c.strength = *v;
     }},
    {"plant", "CASE",
     [](Defaults) {
       return std::string(
           "the plant is another FEM case than the twin (e.g. body-contact "
           "behind --case body); default: the twin itself");
     },
     [](Arguments& a, ExperimentConfig& c) {
       if (const auto v = a.text("plant")) c.plant_case = parse_enum<TwinCase>(*v, "--plant");
     }},
    {"plant-nonlinearity", "K",
     [](Defaults) {
       return fmt::format("the analytic plant's nonlinearity, which the twin lacks: {}",
                          choices<Nonlinearity>());
     },
     [](Arguments& a, ExperimentConfig& c) {
       if (const auto v = a.text("plant-nonlinearity")) {
         c.plant_nonlinearity = parse_enum<Nonlinearity>(*v, "--plant-nonlinearity");
       }
     }},
    {"plant-strength", "S",
     [](Defaults) { return std::string("its strength (default: --strength)"); },
     [](Arguments& a, ExperimentConfig& c) {
       if (const auto v = a.real("plant-strength")) c.plant_strength = *v;
     }},
    {"filter", "NAME",
     [](Defaults d) {
       return fmt::format(
           "sigma points of the filter: {} (merwe: the paper's UKF; cubature: "
           "CKF; default {})",
           choices<FilterScheme>(), to_string(d.filter));
     },
     [](Arguments& a, ExperimentConfig& c) {
       if (const auto v = a.text("filter")) c.filter = parse_enum<FilterScheme>(*v, "--filter");
     }},
    {"sampler", "NAME",
     [](Defaults d) {
       return fmt::format("candidates of the w-controllers: {} (default {})",
                          choices<CandidateSampler>(), to_string(d.sampler));
     },
     [](Arguments& a, ExperimentConfig& c) {
       if (const auto v = a.text("sampler")) {
         c.sampler = parse_enum<CandidateSampler>(*v, "--sampler");
       }
     }},
    {"exploration", "NAME",
     [](Defaults d) {
       return fmt::format("exploration loss of the w-controllers: {} (default {})",
                          choices<ExplorationKind>(), to_string(d.exploration));
     },
     [](Arguments& a, ExperimentConfig& c) {
       if (const auto v = a.text("exploration")) {
         c.exploration = parse_enum<ExplorationKind>(*v, "--exploration");
       }
     }},
    {"candidates", "N",
     [](Defaults) { return std::string("candidates per assembly (default the paper's 2^(2+d))"); },
     [](Arguments& a, ExperimentConfig& c) {
       if (const auto v = a.integer("candidates")) c.candidates = *v;
     }},
    {"controllers", "LIST",
     [](Defaults) {
       return std::string(
           "comma-separated: baseline, nominal, default, w=<0..1>, active, "
           "per-component:w=<0..1>, or \"paper\" (default paper: baseline, "
           "default, w=0, 0.1, ..., 1, active)");
     },
     [](Arguments& a, ExperimentConfig& c) {
       if (const auto v = a.text("controllers")) c.controllers = parse_controllers(*v);
     }},
    {"twin-command", "\"CMD\"",
     [](Defaults) {
       return std::string(
           "the program of the external case (overrides external_twin.command "
           "of --config, which describes the twin: docs/external.md)");
     },
     [](Arguments& a, ExperimentConfig& c) { apply_twin_options(a, std::span(&c, 1)); }},
    {"twin-workers", "N",
     [](Defaults) {
       return fmt::format(
           "processes of the external twin (default {}; results do not depend "
           "on N)",
           ExternalTwinSettings{}.workers);
     },
     nullptr},
});

// A line of help: "  --flag VALUE" in a column of 25, then `text` wrapped at 100 columns.
std::string help_line(std::string_view flag, std::string_view value_name, std::string_view text) {
  constexpr std::size_t column = 25;
  constexpr std::size_t width = 100;
  std::string line = fmt::format("  --{}", flag);
  if (!value_name.empty()) fmt::format_to(std::back_inserter(line), " {}", value_name);
  // A flag too long for its column puts one space before the text.
  line.append(line.size() < column ? column - line.size() : 1, ' ');
  std::size_t used = line.size();
  std::size_t begin = 0;
  bool first_word = true;
  while (begin < text.size()) {
    const std::size_t space = text.find(' ', begin);
    const std::size_t end = space == std::string_view::npos ? text.size() : space;
    const std::string_view word = text.substr(begin, end - begin);
    if (!first_word && used + 1 + word.size() > width) {
      line.append("\n").append(column, ' ');
      used = column;
    } else if (!first_word) {
      line.push_back(' ');
      ++used;
    }
    line.append(word);
    used += word.size();
    first_word = false;
    begin = end + 1;
  }
  line.push_back('\n');
  return line;
}

}  // namespace

std::span<const ConfigOption> config_options() { return options; }

std::string config_options_help() {
  const ExperimentConfig defaults;
  std::string help = help_line(
      "config", "FILE.json", "base config (docs/cli.md has every key); options below override it");
  for (const ConfigOption& option : options) {
    help += help_line(option.flag, option.value_name, option.help(defaults));
  }
  return help;
}

ExperimentConfig read_config(Arguments& arguments,
                             const std::vector<ControllerSpec>& default_controllers) {
  ExperimentConfig config;
  config.controllers = default_controllers;
  if (const auto path = arguments.text("config")) {
    const json document = read_config_file(*path);
    config = document;
    if (!document.contains("controllers")) config.controllers = default_controllers;
  }
  for (const ConfigOption& option : options) {
    if (option.apply != nullptr) option.apply(arguments, config);
  }
  // `twincal serve --controller LABEL` (serve's help lists it): one controller.
  if (const auto v = arguments.text("controller")) config.controllers = parse_controllers(*v);
  return config;
}

void apply_twin_options(Arguments& arguments, std::span<ExperimentConfig> configs) {
  const auto twin_command = arguments.text("twin-command");
  const auto twin_workers = arguments.integer("twin-workers");
  if (!twin_command && !twin_workers) return;
  const std::string option = twin_command ? "--twin-command" : "--twin-workers";
  for (ExperimentConfig& config : configs) {
    if (!config.external_twin) {
      throw InvalidArgumentError(
          option, fmt::format("{}: the config has no external_twin; rule: give --config "
                              "FILE.json whose external_twin describes the twin (its locators "
                              "and bounds; docs/external.md)",
                              option));
    }
    if (twin_command) from_json(json{{"command", *twin_command}}, *config.external_twin);
    if (twin_workers) config.external_twin->workers = *twin_workers;
  }
}

}  // namespace twincal::cli
