#pragma once
/// @file
/// `ExperimentGroup`: one configuration of a study (a case × locator set of the paper's matrix,
/// or one point of a sweep) with the tags that say where it sits in the study (e.g.
/// {"filter": "cubature", "w": 0.3}); its episodes are `config.runs` × `config.controllers`.

#include <nlohmann/json.hpp>

#include "twincal/experiments/experiment_config.hpp"

namespace twincal {

struct ExperimentGroup {
  ExperimentConfig config;
  nlohmann::json tags = nlohmann::json::object();
};

}  // namespace twincal
