#pragma once
/// @file
/// Studies as lists of experiment groups: the paper's matrix (Sec. 3: each case × locator sets
/// A, B, C, ABC × the 13 controllers) and ablation sweeps — the cartesian product of axes over a
/// base config, e.g.
///   {"base": {"case": "analytic", "locators": "ABC", "runs": 5},
///    "axes": {"filter": ["merwe", "cubature"], "w": [0.3, 1.0]}}
/// An axis is any ExperimentConfig key, or one of the shorthands "w" (controllers = ["w=<v>"]),
/// "controller" (controllers = [<v>]) and "dimension" (analytic_dimension). Each point is a
/// group named "<base group>/<key>=<value> …" and tagged with its axis values.

#include <span>
#include <vector>

#include <nlohmann/json.hpp>

#include "twincal/core/eigen.hpp"
#include "twincal/experiments/experiment_choices.hpp"
#include "twincal/experiments/experiment_config.hpp"
#include "twincal/experiments/experiment_group.hpp"

namespace twincal {

/// The paper's matrix for `cases`: locator sets A, B, C, ABC of each case over `base` (whose
/// case and locators are replaced; its name must be empty). Tagged {"case", "locators"}.
[[nodiscard]] std::vector<ExperimentGroup> paper_study(std::span<const TwinCase> cases,
                                                       const ExperimentConfig& base = {});

/// The scaling study: cost and accuracy against the number d of controlled locators. For the
/// analytic twin, one group per d in `dimensions` with every locator controlled, named
/// "analytic/all/d=<d>"; for body and door (whose d is fixed), locator sets A, ABC and all
/// (`dimensions` must then be empty). Groups are tagged {"study": "scaling"} and their
/// "dimension" or "locators"; their d is the length of the twin's locator list in the results.
/// `base`'s case, locators and dimension are replaced (its name must be empty).
/// @throws InvalidArgumentError for a named base, a d < 1, dimensions given for a FEM case.
[[nodiscard]] std::vector<ExperimentGroup> scaling_study(TwinCase twin_case,
                                                         std::span<const Index> dimensions,
                                                         const ExperimentConfig& base = {});

/// The nonlinearity study: accuracy against the strength of the analytic twin's nonlinearity
/// (`base.nonlinearity`, not none), one group per d in `dimensions` and strength s in
/// `strengths`, every locator controlled, named "analytic/all/<nonlinearity>/d=<d>/s=<s>" and
/// tagged {"study": "nonlinearity", "nonlinearity", "dimension", "strength"}; each group's results
/// record how far its Q² departs from a quadratic. `base`'s case, locators, dimension and
/// strength are replaced (its name must be empty).
/// @throws InvalidArgumentError for a named base, nonlinearity none, empty lists, a d < 1 or a
///         strength the nonlinearity refuses.
[[nodiscard]] std::vector<ExperimentGroup> nonlinearity_study(std::span<const Index> dimensions,
                                                              std::span<const double> strengths,
                                                              const ExperimentConfig& base);

/// The groups of a sweep document (see the file comment). Axes are expanded in the order of the
/// document's keys (alphabetical), the last one fastest.
/// @throws InvalidArgumentError naming a missing "base", an empty axis, or a bad value.
[[nodiscard]] std::vector<ExperimentGroup> expand_sweep(const nlohmann::json& sweep);

}  // namespace twincal
