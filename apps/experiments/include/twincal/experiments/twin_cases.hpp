#pragma once
/// @file
/// The twin cases by name: `make_twin` builds the full twin of a case — body and door are the
/// open FEM sheet-metal twin (SheetMetalTwin, 12 and 19 locators), analytic is the
/// RmsQuadraticTwin of `analytic_dimension` locators named A, B, C, … — and `make_case_twin`
/// restricts it to the configured locator set. This file is the one place where case names meet
/// twin types.

#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "twincal/core/eigen.hpp"
#include "twincal/experiments/any_twin.hpp"
#include "twincal/experiments/case_twin.hpp"
#include "twincal/experiments/experiment_config.hpp"
#include "twincal/experiments/experiment_group.hpp"
#include "twincal/experiments/external_case_twin.hpp"

namespace twincal {

/// The full twin of `config.twin_case` with `config.twin_seed` (and `analytic_dimension`); an
/// external twin runs on what `backend` makes (by default its own ExternalTwinPool).
[[nodiscard]] AnyTwin make_twin(const ExperimentConfig& config,
                                const ExternalTwinBackendFactory& backend = {});

/// The plant of `config` when it is not the twin (plant_case, or plant_nonlinearity with its
/// strength): the twin of that setting; std::nullopt when the plant is the twin.
/// @throws InvalidArgumentError for an invalid config.
[[nodiscard]] std::optional<AnyTwin> make_plant(const ExperimentConfig& config,
                                                const ExternalTwinBackendFactory& backend = {});

/// Locator indices of a locator-set spelling (see ExperimentConfig::locators): "A", "B", "C",
/// "ABC" (the twin's significant locators), "all", or names / 0-based indices joined by commas.
/// @throws InvalidArgumentError naming an unknown locator or a set the twin cannot provide.
[[nodiscard]] std::vector<Index> resolve_locators(const AnyTwin& twin, std::string_view spelling);
/// The same from a twin's locator names and significant locators alone (a twin that is a
/// program need not be started to resolve them).
[[nodiscard]] std::vector<Index> resolve_locators(const std::vector<std::string>& names,
                                                  const std::vector<Index>& significant,
                                                  std::string_view spelling);
/// The significant locators (A, B, C) of an external twin with these locator names: its first
/// three.
[[nodiscard]] std::vector<Index> external_significant_locators(Index dimension);

/// make_twin restricted to resolve_locators(config.locators).
[[nodiscard]] CaseTwin make_case_twin(const ExperimentConfig& config);

/// make_case_twin for every group, building one full twin per (case, twin seed, analytic
/// dimension) and sharing it among the groups that restrict it: an FEM twin costs more to build
/// than a whole group's episodes.
[[nodiscard]] std::vector<CaseTwin> make_case_twins(std::span<const ExperimentGroup> groups,
                                                    const ExternalTwinBackendFactory& backend = {});

}  // namespace twincal
