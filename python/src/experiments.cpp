// run_experiment: one group of the paper's protocol (apps/experiments) from a Python dict — the
// FEM and analytic twins, every controller `twincal run` knows — into a results directory, and
// its summary rows back. The dict crosses as JSON text (python/twincal/__init__.py dumps it),
// so the config keys are docs/cli.md's.
#include <set>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <pybind11/pybind11.h>
#include <nlohmann/json.hpp>

#include "bindings.hpp"
#include "twincal/core/error.hpp"
#include "twincal/experiments/controller_spec.hpp"
#include "twincal/experiments/experiment_choices.hpp"
#include "twincal/experiments/experiment_config.hpp"
#include "twincal/experiments/experiment_group.hpp"
#include "twincal/experiments/experiment_runner.hpp"
#include "twincal/experiments/result_store.hpp"
#include "twincal/experiments/summary_table.hpp"

namespace py = pybind11;

namespace twincal::python {
namespace {

ExperimentConfig parse_config(const std::string& text) {
  try {
    const nlohmann::json document = nlohmann::json::parse(text);
    ExperimentConfig config = document;
    if (!document.contains("controllers")) config.controllers = ControllerSpec::paper();
    return config;
  } catch (const nlohmann::json::exception& error) {
    throw InvalidArgumentError("config", fmt::format("config: {}", error.what()));
  }
}

// Runs the group into `out` (episodes already there are kept) and returns
// {"config": …, "rows": [one object per controller]} as JSON text.
std::string run_experiment_json(const std::string& config_text, const std::string& out,
                                Index threads) {
  const ExperimentConfig config = parse_config(config_text);
  RunOptions options;
  options.threads = threads;
  options.progress = false;
  if (auto problem = options.validate()) throw InvalidArgumentError("threads", *problem);
  const std::vector<ExperimentGroup> groups{ExperimentGroup{
      config,
      nlohmann::json{{"case", to_string(config.twin_case)}, {"locators", config.locators}}}};
  nlohmann::json rows = nlohmann::json::array();
  {
    py::gil_scoped_release release;
    ResultStore store(out);
    run_experiments(groups, store, options);
    for (const SummaryRow& row : summarize(store.groups(), store.episodes())) {
      if (row.group != config.group_name()) continue;
      rows.push_back(
          {{"group", row.group},
           {"controller", row.controller},
           {"runs", row.runs},
           {"diverged", row.divergences},
           {"lost", row.lost ? nlohmann::json(*row.lost) : nlohmann::json(nullptr)},
           {"fallbacks", row.fallbacks ? nlohmann::json(*row.fallbacks) : nlohmann::json(nullptr)},
           {"dropped_measurements", row.dropped_measurements
                                        ? nlohmann::json(*row.dropped_measurements)
                                        : nlohmann::json(nullptr)},
           {"median_relative_residual", row.median_relative_residual},
           {"median_estimation_error", row.median_estimation_error},
           {"seconds_per_assembly", row.seconds_per_assembly},
           {"q_evaluations_per_assembly", row.q_evaluations_per_assembly}});
    }
  }
  return nlohmann::json{{"config", config}, {"rows", rows}}.dump();
}

}  // namespace

void bind_experiments(py::module_& module) {
  module.def("_run_experiment", &run_experiment_json, py::arg("config_json"), py::arg("out"),
             py::arg("threads"),
             "run_experiment's compiled half: the config as JSON text, the results directory, "
             "worker threads (0: all cores); returns the summary as JSON text.");
}

}  // namespace twincal::python
