#pragma once
/// @file
/// `CubatureKalmanFilter<StateModel, MeasurementModel>`: a SigmaPointFilter with the
/// third-degree spherical-radial cubature points (Arasaratnam and Haykin 2009). filterpy's CKF
/// reuses the propagated points in its update: SigmaPointFilterOptions::filterpy(
/// SigmaPointRefresh::reuse_propagated) reproduces it.

#include "twincal/filters/sigma_point_filter.hpp"
#include "twincal/filters/spherical_radial_sigma_points.hpp"

namespace twincal {

template <StateModel SM, MeasurementModel MM>
using CubatureKalmanFilter = SigmaPointFilter<SM, MM, SphericalRadialSigmaPoints>;

}  // namespace twincal
