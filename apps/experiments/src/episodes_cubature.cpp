// CKF episodes (spherical-radial cubature points), fixed d = 1, 3 and dynamic d.
#include "episode_simulation.hpp"
#include "twincal/filters/spherical_radial_sigma_points.hpp"

namespace twincal::detail {

template void run_filtered<1, SphericalRadialSigmaPoints>(const EpisodeSetup&,
                                                          const ControllerSpec&,
                                                          const SphericalRadialSigmaPoints&,
                                                          EpisodeResult&);
template void run_filtered<3, SphericalRadialSigmaPoints>(const EpisodeSetup&,
                                                          const ControllerSpec&,
                                                          const SphericalRadialSigmaPoints&,
                                                          EpisodeResult&);
template void run_filtered<Dynamic, SphericalRadialSigmaPoints>(const EpisodeSetup&,
                                                                const ControllerSpec&,
                                                                const SphericalRadialSigmaPoints&,
                                                                EpisodeResult&);

}  // namespace twincal::detail
