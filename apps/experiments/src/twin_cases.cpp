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

#include "twincal/core/error.hpp"
#include "twincal/core/options.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/experiments/external_case_twin.hpp"
#include "twincal/models/rms_quadratic_twin.hpp"

// The FEM twin joins the build in models/; until its header exists the body and door cases
// report that they are unavailable.
#if __has_include("twincal/models/sheet_metal_twin.hpp")
#include "twincal/models/sheet_metal_twin.hpp"
#define TWINCAL_HAS_SHEET_METAL_TWIN 1
#else
#define TWINCAL_HAS_SHEET_METAL_TWIN 0
#endif

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

AnyTwin analytic_twin(const ExperimentConfig& config) {
  RmsQuadraticTwinOptions options;
  options.assemblies.dimension = config.analytic_dimension;
  options.assemblies.locator_names = letter_names(config.analytic_dimension);
  RmsQuadraticTwin twin = RmsQuadraticTwin::generate(options, RandomStream(config.twin_seed));
  std::vector<AssemblyId> assemblies = twin.assemblies();
  std::vector<Index> significant;
  for (Index i = 0; i < std::min<Index>(3, config.analytic_dimension); ++i)
    significant.push_back(i);
  return {std::move(twin), std::move(assemblies), std::move(significant)};
}

}  // namespace

bool sheet_metal_cases_available() noexcept { return TWINCAL_HAS_SHEET_METAL_TWIN != 0; }

// The program's twin; its first three locators are A, B, C.
AnyTwin external_twin(const ExperimentConfig& config) {
  require_valid("config", config);
  ExternalCaseTwin twin(*config.external_twin);
  std::vector<AssemblyId> assemblies = twin.assemblies();
  std::vector<Index> significant;
  for (Index i = 0; i < std::min<Index>(3, twin.control_dimension()); ++i) {
    significant.push_back(i);
  }
  return {std::move(twin), std::move(assemblies), std::move(significant)};
}

AnyTwin make_twin(const ExperimentConfig& config) {
  if (config.twin_case == TwinCase::analytic) return analytic_twin(config);
  if (config.twin_case == TwinCase::external) return external_twin(config);
#if TWINCAL_HAS_SHEET_METAL_TWIN
  SheetMetalTwin twin = SheetMetalTwin::make(
      config.twin_case == TwinCase::body ? SheetMetalCase::body : SheetMetalCase::door,
      config.twin_seed);
  std::vector<AssemblyId> assemblies = twin.assemblies();
  const auto significant = twin.significant_locators();
  return {std::move(twin), std::move(assemblies),
          std::vector<Index>(significant.begin(), significant.end())};
#else
  throw InvalidArgumentError(
      "case", fmt::format("case: is \"{}\"; rule: the FEM sheet-metal twin is not part of this "
                          "build, so only \"analytic\" is available",
                          to_string(config.twin_case)));
#endif
}

std::vector<Index> resolve_locators(const AnyTwin& twin, std::string_view spelling) {
  const std::vector<Index>& significant = twin.significant_locators();
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
    std::vector<Index> all(static_cast<std::size_t>(twin.control_dimension()));
    for (std::size_t i = 0; i < all.size(); ++i) all[i] = static_cast<Index>(i);
    return all;
  }
  const std::vector<std::string>& names = twin.locator_names();
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
          index >= twin.control_dimension()) {
        throw InvalidArgumentError(
            "locators",
            fmt::format("locators: \"{}\" in \"{}\" is unknown; rule: must be A, B, C, ABC, all, "
                        "or names of [{}] or indices in [0, {}] joined by commas",
                        token, spelling, fmt::join(names, ", "), twin.control_dimension() - 1));
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
  return {std::move(twin), std::move(locators)};
}

std::vector<CaseTwin> make_case_twins(std::span<const ExperimentGroup> groups) {
  std::map<std::tuple<TwinCase, std::uint64_t, Index, std::string>, AnyTwin> full_twins;
  std::vector<CaseTwin> twins;
  twins.reserve(groups.size());
  for (const ExperimentGroup& group : groups) {
    const ExperimentConfig& config = group.config;
    // An external twin is its program: groups of different programs get their own pools.
    const auto key = std::tuple(
        config.twin_case, config.twin_seed,
        config.twin_case == TwinCase::analytic ? config.analytic_dimension : Index{0},
        config.external_twin ? nlohmann::json(*config.external_twin).dump() : std::string());
    auto full = full_twins.find(key);
    if (full == full_twins.end()) full = full_twins.emplace(key, make_twin(config)).first;
    twins.emplace_back(full->second, resolve_locators(full->second, config.locators));
  }
  return twins;
}

}  // namespace twincal
