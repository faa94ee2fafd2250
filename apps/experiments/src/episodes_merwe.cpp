// The paper's UKF episodes (van der Merwe's scaled points), fixed d = 1, 3 and dynamic d.
#include "episode_simulation.hpp"
#include "twincal/filters/merwe_scaled_sigma_points.hpp"

namespace twincal::detail {

TWINCAL_MERWE_EPISODES(TWINCAL_INSTANTIATE_EPISODES)

}  // namespace twincal::detail
