// The per-component episodes (controllers' per_component_controller.hpp): one paper w-controller
// (UKF with Merwe's points, scrambled Sobol candidates, trace loss) per locator, with the config's
// filter numbers, w, box, candidate count and cap. The components are one-dimensional whatever d
// is.
#include "episode_simulation.hpp"
#include "twincal/controllers/per_component_controller.hpp"

namespace twincal::detail {

AnyController make_per_component(const EpisodeSetup& setup, const ControllerSpec& spec) {
  const ExperimentConfig& config = *setup.config;
  return AnyController(make_per_component_paper_controller(
                           *setup.twin, setup.run.substream("filter"),
                           lookahead_options(config, spec, 1), paper_settings(config)),
                       setup.twin->control_dimension());
}

}  // namespace twincal::detail
