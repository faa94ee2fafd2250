#pragma once
/// @file
/// Umbrella header of the calculix module: the CalculiX assembly twin and its
/// influence-coefficient linearization (docs/calculix.md).

#include "twincal/calculix/calculix_error.hpp"
#include "twincal/calculix/calculix_model.hpp"
#include "twincal/calculix/calculix_options.hpp"
#include "twincal/calculix/calculix_process.hpp"
#include "twincal/calculix/calculix_results.hpp"
#include "twincal/calculix/calculix_twin.hpp"
#include "twincal/calculix/influence_coefficient_twin.hpp"
