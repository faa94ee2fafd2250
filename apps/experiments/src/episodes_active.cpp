// The active controller's episodes (controllers' active_controller.hpp). The controller itself is
// instantiated once, at dynamic size, for every d.
#include "episode_simulation.hpp"
#include "twincal/controllers/active_controller.hpp"

namespace twincal::detail {

AnyController make_active(const EpisodeSetup& setup) {
  const ExperimentConfig& config = *setup.config;
  ActiveOptions options = config.active;
  options.measurement_variance = config.filter_measurement_variance();
  options.initial_variance = config.initial_variance;
  // The "filter" substream: δû0 is the same draw as the filter-based controllers' of the run.
  return AnyController(
      ActiveController<CaseTwin>(*setup.twin, setup.run.substream("filter"), options),
      setup.twin->control_dimension());
}

}  // namespace twincal::detail
