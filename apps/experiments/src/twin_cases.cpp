#include "twincal/experiments/twin_cases.hpp"

#include <algorithm>
#include <charconv>
#include <map>
#include <string>
#include <system_error>
#include <tuple>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "twincal/controllers/searched_optimum_twin.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/options.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/experiments/external_case_twin.hpp"
#include "twincal/models/contact_nonlinearity.hpp"
#include "twincal/models/key_point_twin.hpp"
#include "twincal/models/kink_nonlinearity.hpp"
#include "twincal/models/no_nonlinearity.hpp"
#include "twincal/models/rms_quadratic_twin.hpp"
#include "twincal/models/stiffening_nonlinearity.hpp"
#include "twincal/sheet_metal/contact_sheet_metal_twin.hpp"
#include "twincal/sheet_metal/sheet_metal_twin.hpp"

namespace twincal {
namespace {

std::vector<std::string> letter_names(Index d) {
  std::vector<std::string> names;
  for (Index i = 0; i < d; ++i) {
    names.push_back(d <= 26 ? std::string(1, static_cast<char>('A' + i))
                            : fmt::format("u{}", i + 1));
  }
  return names;
}

// An analytic or external twin's A, B, C: its first three locators.
std::vector<Index> first_locators(Index d) {
  std::vector<Index> significant;
  for (Index i = 0; i < std::min<Index>(3, d); ++i) significant.push_back(i);
  return significant;
}

KeyPointTwinOptions key_point_options(const ExperimentConfig& config) {
  KeyPointTwinOptions options;
  options.assemblies.dimension = config.analytic_dimension;
  options.assemblies.locator_names = letter_names(config.analytic_dimension);
  options.strength = config.strength;
  return options;
}

template <DeviationNonlinearity Kind>
AnyTwin key_point_twin(const ExperimentConfig& config) {
  KeyPointTwin<Kind> key_points(key_point_options(config), RandomStream(config.twin_seed));
  std::vector<AssemblyId> assemblies = key_points.assemblies();
  // Q² is not a quadratic: u0 and z* are searched, as for a real twin.
  SearchedOptimumTwin<KeyPointTwin<Kind>> twin(std::move(key_points), assemblies);
  return {std::move(twin), std::move(assemblies), first_locators(config.analytic_dimension)};
}

AnyTwin analytic_twin(const ExperimentConfig& config) {
  // Behind a plant with a nonlinearity the twin is the same key-point twin without it (the same
  // influence and residuals), not the RMS-quadratic twin; its optimum is known.
  if (config.nonlinearity == Nonlinearity::none && config.plant_nonlinearity) {
    KeyPointTwin<NoNonlinearity> twin(key_point_options(config), RandomStream(config.twin_seed));
    std::vector<AssemblyId> assemblies = twin.assemblies();
    return {std::move(twin), std::move(assemblies), first_locators(config.analytic_dimension)};
  }
  switch (config.nonlinearity) {
    case Nonlinearity::contact:
      return key_point_twin<ContactNonlinearity>(config);
    case Nonlinearity::stiffening:
      return key_point_twin<StiffeningNonlinearity>(config);
    case Nonlinearity::kink:
      return key_point_twin<KinkNonlinearity>(config);
    case Nonlinearity::none:
      break;
  }
  RmsQuadraticTwinOptions options;
  options.assemblies.dimension = config.analytic_dimension;
  options.assemblies.locator_names = letter_names(config.analytic_dimension);
  RmsQuadraticTwin twin = RmsQuadraticTwin::generate(options, RandomStream(config.twin_seed));
  std::vector<AssemblyId> assemblies = twin.assemblies();
  return {std::move(twin), std::move(assemblies), first_locators(config.analytic_dimension)};
}

// The FEM case with flange contact: the linear case's parts and locators A, B, C; Q² is not a
// quadratic, so u0 and z* are searched (from the linear twin's optimum).
AnyTwin contact_twin(const ExperimentConfig& config) {
  ContactSheetMetalTwin contact = ContactSheetMetalTwin::make(
      config.twin_case == TwinCase::body_contact ? SheetMetalCase::body : SheetMetalCase::door,
      config.twin_seed);
  std::vector<AssemblyId> assemblies = contact.assemblies();
  const auto significant = contact.significant_locators();
  // Contact moves the linear twin's optimum by hundredths of a mm (docs/sheet_metal.md), so a
  // local search from it finds the optimum (same body optima, door z* within 1.5e-5 mm of the
  // global search's, at a fifth of the evaluations).
  SearchedOptimumTwin<ContactSheetMetalTwin> twin(
      std::move(contact), assemblies,
      NloptOptimizer(NloptOptimizerOptions{.global_evaluations = 0}));
  return {std::move(twin), std::move(assemblies),
          std::vector<Index>(significant.begin(), significant.end())};
}

}  // namespace

// The program's twin; its first three locators are A, B, C.
AnyTwin external_twin(const ExperimentConfig& config, const ExternalTwinBackendFactory& backend) {
  require_valid("config", config);
  ExternalCaseTwin twin(*config.external_twin, backend);
  std::vector<AssemblyId> assemblies = twin.assemblies();
  std::vector<Index> significant = first_locators(twin.control_dimension());
  return {std::move(twin), std::move(assemblies), std::move(significant)};
}

AnyTwin make_twin(const ExperimentConfig& config, const ExternalTwinBackendFactory& backend) {
  if (config.twin_case == TwinCase::analytic) return analytic_twin(config);
  if (config.twin_case == TwinCase::external) return external_twin(config, backend);
  if (config.twin_case == TwinCase::body_contact || config.twin_case == TwinCase::door_contact) {
    return contact_twin(config);
  }
  SheetMetalTwin twin = SheetMetalTwin::make(
      config.twin_case == TwinCase::body ? SheetMetalCase::body : SheetMetalCase::door,
      config.twin_seed);
  std::vector<AssemblyId> assemblies = twin.assemblies();
  const auto significant = twin.significant_locators();
  return {std::move(twin), std::move(assemblies),
          std::vector<Index>(significant.begin(), significant.end())};
}

std::optional<AnyTwin> make_plant(const ExperimentConfig& config,
                                  const ExternalTwinBackendFactory& backend) {
  require_valid("config", config);
  ExperimentConfig plant = config;
  plant.plant_case.reset();
  plant.plant_nonlinearity.reset();
  plant.plant_strength.reset();
  plant.plant_external_twin.reset();
  if (config.plant_external_twin) {
    plant.external_twin = *config.plant_external_twin;
    return make_twin(plant, backend);
  }
  if (config.plant_case) {
    plant.twin_case = *config.plant_case;
    return make_twin(plant, backend);
  }
  if (config.plant_nonlinearity) {
    plant.nonlinearity = *config.plant_nonlinearity;
    plant.strength = config.plant_strength.value_or(config.strength);
    return make_twin(plant, backend);
  }
  return std::nullopt;
}

std::vector<Index> resolve_locators(const AnyTwin& twin, std::string_view spelling) {
  return resolve_locators(twin.locator_names(), twin.significant_locators(), spelling);
}

std::vector<Index> external_significant_locators(Index dimension) {
  return first_locators(dimension);
}

std::vector<Index> resolve_locators(const std::vector<std::string>& names,
                                    const std::vector<Index>& significant,
                                    std::string_view spelling) {
  const auto dimension = static_cast<Index>(names.size());
  const auto significant_at = [&](std::size_t i) {
    if (i >= significant.size()) {
      throw InvalidArgumentError(
          "locators", fmt::format("locators: \"{}\" needs significant locator {}; rule: the twin "
                                  "has {} significant locators",
                                  spelling, "ABC"[i], significant.size()));
    }
    return significant[i];
  };
  if (spelling == "A" || spelling == "B" || spelling == "C") {
    return {significant_at(static_cast<std::size_t>(spelling[0] - 'A'))};
  }
  if (spelling == "ABC") return {significant_at(0), significant_at(1), significant_at(2)};
  if (spelling == "all") {
    std::vector<Index> all(static_cast<std::size_t>(dimension));
    for (std::size_t i = 0; i < all.size(); ++i) all[i] = static_cast<Index>(i);
    return all;
  }
  std::vector<Index> locators;
  std::size_t begin = 0;
  while (begin <= spelling.size()) {
    const std::size_t end = std::min(spelling.find(',', begin), spelling.size());
    const std::string_view token = spelling.substr(begin, end - begin);
    const auto named = std::find(names.begin(), names.end(), token);
    Index index = -1;
    if (named != names.end()) {
      index = static_cast<Index>(named - names.begin());
    } else {
      const auto [last, error] = std::from_chars(token.data(), token.data() + token.size(), index);
      if (error != std::errc{} || last != token.data() + token.size() || index < 0 ||
          index >= dimension) {
        throw InvalidArgumentError(
            "locators",
            fmt::format("locators: \"{}\" in \"{}\" is unknown; rule: must be A, B, C, ABC, all, "
                        "or names of [{}] or indices in [0, {}] joined by commas",
                        token, spelling, fmt::join(names, ", "), dimension - 1));
      }
    }
    locators.push_back(index);
    begin = end + 1;
  }
  return locators;
}

CaseTwin make_case_twin(const ExperimentConfig& config) {
  AnyTwin twin = make_twin(config);
  std::vector<Index> locators = resolve_locators(twin, config.locators);
  return {std::move(twin), std::move(locators), make_plant(config)};
}

std::vector<CaseTwin> make_case_twins(std::span<const ExperimentGroup> groups,
                                      const ExternalTwinBackendFactory& backend) {
  // Twins (and plants) are built once per distinct setting: a searched optimum or an external
  // twin's pool is costly.
  std::map<std::string, AnyTwin> full_twins;
  std::map<std::string, std::optional<AnyTwin>> plants;
  std::vector<CaseTwin> twins;
  twins.reserve(groups.size());
  for (const ExperimentGroup& group : groups) {
    const ExperimentConfig& config = group.config;
    // What defines the twin (an external twin is its program: groups of different programs get
    // their own pools), and the plant besides.
    const bool analytic = config.twin_case == TwinCase::analytic;
    const nlohmann::json twin_key{
        {"case", to_string(config.twin_case)},
        {"twin_seed", config.twin_seed},
        {"dimension", analytic ? config.analytic_dimension : Index{0}},
        {"external", config.external_twin ? nlohmann::json(*config.external_twin) : nullptr},
        {"nonlinearity", to_string(config.nonlinearity)},
        {"strength",
         analytic && (config.nonlinearity != Nonlinearity::none || config.plant_nonlinearity)
             ? config.strength
             : 0.0},
        {"plant_nonlinearity", config.plant_nonlinearity.has_value()}};
    const std::string key = twin_key.dump();
    // A plant that is a program of its own does not depend on the twin: groups that differ
    // only in their twin (a sweep over twins against one slow plant) share it and its searched
    // optima. Every other plant is the twin's case changed.
    nlohmann::json plant_key = config.plant_external_twin ? nlohmann::json::object() : twin_key;
    plant_key["plant_case"] =
        config.plant_case ? nlohmann::json(to_string(*config.plant_case)) : nlohmann::json(nullptr);
    plant_key["plant_nonlinearity"] = config.plant_nonlinearity
                                          ? nlohmann::json(to_string(*config.plant_nonlinearity))
                                          : nlohmann::json(nullptr);
    plant_key["plant_strength"] = config.plant_strength.value_or(config.strength);
    plant_key["plant_external"] = config.plant_external_twin
                                      ? nlohmann::json(*config.plant_external_twin)
                                      : nlohmann::json(nullptr);
    auto full = full_twins.find(key);
    if (full == full_twins.end()) full = full_twins.emplace(key, make_twin(config, backend)).first;
    auto plant = plants.find(plant_key.dump());
    if (plant == plants.end()) {
      plant = plants.emplace(plant_key.dump(), make_plant(config, backend)).first;
    }
    twins.emplace_back(full->second, resolve_locators(full->second, config.locators),
                       plant->second);
  }
  return twins;
}

}  // namespace twincal
