// The per-component episodes (controllers' per_component_controller.hpp): one paper w-controller
// (UKF with Merwe's points, scrambled Sobol candidates, trace loss) per locator, with the config's
// filter numbers, w, box, candidate count and cap. The components are one-dimensional whatever d
// is; N only selects the drift's arithmetic, as for every controller of a run
// (episode_simulation.hpp).
#include "episode_simulation.hpp"
#include "twincal/controllers/per_component_controller.hpp"

namespace twincal::detail {

template <int N>
void run_per_component(const EpisodeSetup& setup, const ControllerSpec& spec,
                       EpisodeResult& result) {
  const ExperimentConfig& config = *setup.config;
  auto controller = make_per_component_paper_controller(*setup.twin, setup.run.substream("filter"),
                                                        lookahead_options(config, spec, 1),
                                                        paper_settings(config));
  simulate<N>(controller, setup, result);
}

template void run_per_component<1>(const EpisodeSetup&, const ControllerSpec&, EpisodeResult&);
template void run_per_component<3>(const EpisodeSetup&, const ControllerSpec&, EpisodeResult&);
template void run_per_component<Dynamic>(const EpisodeSetup&, const ControllerSpec&,
                                         EpisodeResult&);

}  // namespace twincal::detail
