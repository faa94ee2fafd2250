// CKF episodes (spherical-radial cubature points), fixed d = 1, 3 and dynamic d.
#include "episode_simulation.hpp"
#include "twincal/filters/spherical_radial_sigma_points.hpp"

namespace twincal::detail {

template AnyController make_filtered<1, SphericalRadialSigmaPoints>(
    const EpisodeSetup&, const ControllerSpec&, const SphericalRadialSigmaPoints&);
template AnyController make_filtered<3, SphericalRadialSigmaPoints>(
    const EpisodeSetup&, const ControllerSpec&, const SphericalRadialSigmaPoints&);
template AnyController make_filtered<Dynamic, SphericalRadialSigmaPoints>(
    const EpisodeSetup&, const ControllerSpec&, const SphericalRadialSigmaPoints&);

}  // namespace twincal::detail
