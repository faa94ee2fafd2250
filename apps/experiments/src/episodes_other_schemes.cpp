// Episodes for the schemes that are ablations only (Julier, fifth-degree cubature, simplex):
// dynamic d, so each costs one instantiation.
#include "episode_simulation.hpp"
#include "twincal/filters/fifth_degree_cubature_sigma_points.hpp"
#include "twincal/filters/julier_sigma_points.hpp"
#include "twincal/filters/simplex_sigma_points.hpp"

namespace twincal::detail {

TWINCAL_OTHER_SCHEME_EPISODES(TWINCAL_INSTANTIATE_EPISODES)

}  // namespace twincal::detail
