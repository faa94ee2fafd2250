#pragma once
/// @file
/// `ExternalTwinSettings`: the `external` twin case of a config — a twin that is a program
/// speaking models' external-twin protocol (external_twin.hpp), run as a pool of `workers`
/// processes (external_twin_pool.hpp). Its assemblies are the pairs of upper_parts × lower_parts
/// parts, sent to the program as {"upper": i, "lower": j}; u0(x) and z*(x) are searched with
/// NLopt from the centre of the bounds (external_case_twin.hpp). JSON (config key
/// `external_twin`, unknown keys rejected):
///   {"command": ["python3", "twin.py"], "locators": ["A", "B", "C"],
///    "lower_bounds": [-1, -1, -1], "upper_bounds": [1, 1, 1],
///    "upper_parts": 10, "lower_parts": 10, "workers": 4, "timeout_ms": 10000,
///    "startup_grace_ms": 10000,
///    "optimum_global_evaluations": 2000, "optimum_local_evaluations": 1000,
///    "optimum_budget": 0, "optimum_method": "bobyqa", "optimum_seed": 2023, "key_points": 0,
///    "optimum_start_command": [], "optima_file": ""}

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "twincal/core/eigen.hpp"

namespace twincal {

struct LeastSquaresSearchOptions;  // controllers/least_squares_search.hpp

struct ExternalTwinSettings {
  std::vector<std::string> command;   ///< argv; command[0] is looked up in PATH if bare
  std::vector<std::string> locators;  ///< the twin's d locator names, in its control order
  std::vector<double> lower_bounds;   ///< d finite bounds of the controls
  std::vector<double> upper_bounds;   ///< d finite bounds, each > its lower bound
  Index upper_parts = 10;             ///< assemblies: upper_parts × lower_parts pairs
  Index lower_parts = 10;
  Index workers = 1;         ///< processes of the pool; does not change any result
  Index timeout_ms = 10000;  ///< longest wait for one reply
  /// Added to timeout_ms for a freshly started process's first reply (an interpreter or a
  /// solver that loads a model before it answers); does not change any result.
  Index startup_grace_ms = 10000;
  /// Budgets of the u0(x) search per assembly (NLopt's DIRECT-L, then BOBYQA; controllers'
  /// nlopt_optimizer.hpp): every evaluation is one request, so a slow twin wants them small.
  Index optimum_global_evaluations = 2000;
  Index optimum_local_evaluations = 1000;
  /// A budgeted u0(x) search instead (the two budgets above are then unused): 0 searches as
  /// above; B > 0 runs BOBYQA alone with B evaluations per assembly, from the additive warm
  /// start u0(i, 0) + u0(0, j) − u0(0, 0) (controllers' additive_warm_start.hpp), and with 2B
  /// from the centre for the first row and column of assemblies and for scanned ones.
  Index optimum_budget = 0;
  /// How a budgeted search runs: "bobyqa" (NLopt's BOBYQA, one evaluation per request),
  /// "trust_region" (controllers' TrustRegionSearch on Q: 2d + 1 controls in its first request,
  /// d + 1 in each later one), "least_squares" (controllers' LeastSquaresSearch on the key
  /// points' deviations, for a twin that answers them: `key_points` > 0; d controls per
  /// Jacobian, one per step) or "least_squares_speculative" (the same search asking for each
  /// start and step with the Jacobian's stencil there, d + 1 controls per request:
  /// LeastSquaresSearchOptions::speculative_jacobian). Each assembly's requests go to one
  /// worker. The trust region waits on the twin 10 to 25 times less often than BOBYQA and its
  /// batches can share a solver deck; least squares crosses the kinks of contact that stall both
  /// (docs/benchmarks.md, "Budgeted u0"). Unused when optimum_budget is 0.
  std::string optimum_method = "bobyqa";
  /// Seed of the least-squares search's restarts; assembly x draws from
  /// RandomStream(optimum_seed).substream(<x as the program receives it, compact JSON>), so a
  /// search does not depend on the workers or the order of the searches.
  std::uint64_t optimum_seed = 2023;
  /// A fast twin of the same assemblies, locators and bounds (argv, as `command`; e.g. the
  /// influence-coefficient map of a slow solver, docs/calculix.md): with a budgeted search, each
  /// assembly's u0 is first searched in full on it (optimum_global_evaluations and
  /// optimum_local_evaluations, by one process of its own: a fast twin's searches are quick, its
  /// construction may not be, and a pool would repeat it per process), and that optimum starts
  /// the budgeted search on this twin with B evaluations, the first row and column and scanned
  /// assemblies too, instead of the additive warm start and 2B from the centre. Empty (the
  /// default): no start twin. Its evaluations are its own, not counted as this twin's
  /// (ExternalCaseTwin::start_search_evaluations()).
  std::vector<std::string> optimum_start_command;
  /// m, the key points whose deviations r(x, u) the program answers when a request asks for
  /// them (Q = ‖r‖ / √m; docs/external.md); 0 for a program that answers qualities only.
  Index key_points = 0;
  /// A file of the pairs' searched u0(x) and z*(x) (searched_optima_file.hpp; a path relative
  /// to the working directory): the pairs it holds are read instead of searched — it must have
  /// been searched under these settings —, the others searched and written to it one by one, so
  /// an interrupted search resumes. "" (the default): search every time. A slow program's search
  /// then runs once per file rather than once per study; delete the file when the program
  /// changes.
  std::string optima_file;

  static constexpr Index max_parts = 10000;
  static constexpr Index max_key_points = 1000000;

  [[nodiscard]] std::optional<std::string> validate() const;
};

/// Whether a budgeted u0 search with `method` runs controllers' LeastSquaresSearch (on the key
/// points' deviations): "least_squares" and "least_squares_speculative".
[[nodiscard]] bool least_squares_method(const std::string& method) noexcept;
/// The LeastSquaresSearch of a least-squares `method` within `evaluations`: speculative
/// Jacobians for "least_squares_speculative", the defaults otherwise.
[[nodiscard]] LeastSquaresSearchOptions least_squares_options(const std::string& method,
                                                              std::uint64_t evaluations);

void to_json(nlohmann::json& json, const ExternalTwinSettings& settings);
/// The settings as JSON without the fields that change no result: the pool's size and patience
/// (workers, timeout_ms, startup_grace_ms), optima_file, and key_points and optimum_seed unless
/// the u0 search is a budgeted least-squares one. What identifies a group's episodes
/// (experiment_config.hpp) and a file of searched optima (searched_optima_file.hpp).
[[nodiscard]] nlohmann::json result_defining_json(const ExternalTwinSettings& settings);
/// @throws InvalidArgumentError naming an unknown key or a value of the wrong type.
void from_json(const nlohmann::json& json, ExternalTwinSettings& settings);

}  // namespace twincal
