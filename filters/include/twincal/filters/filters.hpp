#pragma once
/// @file
/// Umbrella header of the filters module: sigma-point schemes, the sigma-point Kalman filters
/// (standard and square-root form) and their concepts.

#include "twincal/filters/cubature_kalman_filter.hpp"
#include "twincal/filters/fifth_degree_cubature_sigma_points.hpp"
#include "twincal/filters/filter_scheme.hpp"
#include "twincal/filters/fixed_size_kernels.hpp"
#include "twincal/filters/julier_sigma_points.hpp"
#include "twincal/filters/measurement_model.hpp"
#include "twincal/filters/measurement_preview.hpp"
#include "twincal/filters/merwe_scaled_sigma_points.hpp"
#include "twincal/filters/quadratic_quality_measurement.hpp"
#include "twincal/filters/sigma_point_filter.hpp"
#include "twincal/filters/sigma_point_filter_options.hpp"
#include "twincal/filters/sigma_point_scheme.hpp"
#include "twincal/filters/sigma_points.hpp"
#include "twincal/filters/simplex_sigma_points.hpp"
#include "twincal/filters/spherical_radial_sigma_points.hpp"
#include "twincal/filters/square_root_sigma_point_filter.hpp"
#include "twincal/filters/state_model.hpp"
#include "twincal/filters/symmetric_pairs.hpp"
#include "twincal/filters/unscented_kalman_filter.hpp"
#include "twincal/filters/unscented_transform.hpp"
