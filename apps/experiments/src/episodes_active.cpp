// The active controller's episodes (controllers' active_controller.hpp). The controller itself is
// instantiated once, at dynamic size; N only selects the drift's arithmetic, as for every
// controller of a run (episode_simulation.hpp).
#include "episode_simulation.hpp"
#include "twincal/controllers/active_controller.hpp"

namespace twincal::detail {

template <int N>
void run_active(const EpisodeSetup& setup, EpisodeResult& result) {
  const ExperimentConfig& config = *setup.config;
  ActiveOptions options;
  options.measurement_variance = config.filter_measurement_variance();
  options.initial_variance = config.initial_variance;
  // The "filter" substream: δû0 is the same draw as the filter-based controllers' of the run.
  ActiveController<CaseTwin> controller(*setup.twin, setup.run.substream("filter"), options);
  simulate<N>(controller, setup, result);
}

template void run_active<1>(const EpisodeSetup&, EpisodeResult&);
template void run_active<3>(const EpisodeSetup&, EpisodeResult&);
template void run_active<Dynamic>(const EpisodeSetup&, EpisodeResult&);

}  // namespace twincal::detail
