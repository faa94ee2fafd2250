// CKF episodes (spherical-radial cubature points), fixed d = 1, 3 and dynamic d.
#include "episode_simulation.hpp"
#include "twincal/filters/spherical_radial_sigma_points.hpp"

namespace twincal::detail {

TWINCAL_CUBATURE_EPISODES(TWINCAL_INSTANTIATE_EPISODES)

}  // namespace twincal::detail
