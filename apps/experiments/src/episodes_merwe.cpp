// The paper's UKF episodes (van der Merwe's scaled points), fixed d = 1, 3 and dynamic d.
#include "episode_simulation.hpp"
#include "twincal/filters/merwe_scaled_sigma_points.hpp"

namespace twincal::detail {

template AnyController make_filtered<1, MerweScaledSigmaPoints>(const EpisodeSetup&,
                                                                const ControllerSpec&,
                                                                const MerweScaledSigmaPoints&);
template AnyController make_filtered<3, MerweScaledSigmaPoints>(const EpisodeSetup&,
                                                                const ControllerSpec&,
                                                                const MerweScaledSigmaPoints&);
template AnyController make_filtered<Dynamic, MerweScaledSigmaPoints>(
    const EpisodeSetup&, const ControllerSpec&, const MerweScaledSigmaPoints&);

}  // namespace twincal::detail
