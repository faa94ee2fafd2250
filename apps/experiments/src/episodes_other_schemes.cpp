// Episodes for the schemes that are ablations only (Julier, fifth-degree cubature, simplex):
// dynamic d, so each costs one instantiation.
#include "episode_simulation.hpp"
#include "twincal/filters/fifth_degree_cubature_sigma_points.hpp"
#include "twincal/filters/julier_sigma_points.hpp"
#include "twincal/filters/simplex_sigma_points.hpp"

namespace twincal::detail {

template void run_filtered<Dynamic, JulierSigmaPoints>(const EpisodeSetup&, const ControllerSpec&,
                                                       const JulierSigmaPoints&, EpisodeResult&);
template void run_filtered<Dynamic, FifthDegreeCubatureSigmaPoints>(
    const EpisodeSetup&, const ControllerSpec&, const FifthDegreeCubatureSigmaPoints&,
    EpisodeResult&);
template void run_filtered<Dynamic, SimplexSigmaPoints>(const EpisodeSetup&, const ControllerSpec&,
                                                        const SimplexSigmaPoints&, EpisodeResult&);

}  // namespace twincal::detail
