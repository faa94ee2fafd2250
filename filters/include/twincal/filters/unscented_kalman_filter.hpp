#pragma once
/// @file
/// `UnscentedKalmanFilter<StateModel, MeasurementModel>`: the paper's filter (Sec. 2.3.1;
/// sigma points of eq. (11)), a SigmaPointFilter with van der Merwe's scaled sigma points. The
/// scheme's α, β, κ have no defaults: pass MerweScaledSigmaPoints{α, β, κ} to the constructor.

#include "twincal/filters/merwe_scaled_sigma_points.hpp"
#include "twincal/filters/sigma_point_filter.hpp"

namespace twincal {

template <StateModel SM, MeasurementModel MM>
using UnscentedKalmanFilter = SigmaPointFilter<SM, MM, MerweScaledSigmaPoints>;

}  // namespace twincal
