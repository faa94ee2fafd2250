// Episodes for the schemes that are ablations only (Julier, fifth-degree cubature, simplex):
// dynamic d, so each costs one instantiation.
#include "episode_simulation.hpp"
#include "twincal/filters/fifth_degree_cubature_sigma_points.hpp"
#include "twincal/filters/julier_sigma_points.hpp"
#include "twincal/filters/simplex_sigma_points.hpp"

namespace twincal::detail {

template AnyController make_filtered<Dynamic, JulierSigmaPoints>(const EpisodeSetup&,
                                                                 const ControllerSpec&,
                                                                 const JulierSigmaPoints&);
template AnyController make_filtered<Dynamic, FifthDegreeCubatureSigmaPoints>(
    const EpisodeSetup&, const ControllerSpec&, const FifthDegreeCubatureSigmaPoints&);
template AnyController make_filtered<Dynamic, SimplexSigmaPoints>(const EpisodeSetup&,
                                                                  const ControllerSpec&,
                                                                  const SimplexSigmaPoints&);

}  // namespace twincal::detail
