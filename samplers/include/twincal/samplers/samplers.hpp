#pragma once
/// @file
/// Umbrella header of the samplers module.

#include "twincal/samplers/any_sampler.hpp"
#include "twincal/samplers/balance_check.hpp"
#include "twincal/samplers/box_set.hpp"
#include "twincal/samplers/candidate_sampler.hpp"
#include "twincal/samplers/candidates.hpp"
#include "twincal/samplers/discrepancy.hpp"
#include "twincal/samplers/gaussian_transform.hpp"
#include "twincal/samplers/halton.hpp"
#include "twincal/samplers/latin_hypercube.hpp"
#include "twincal/samplers/normal_quantile.hpp"
#include "twincal/samplers/pseudo_random.hpp"
#include "twincal/samplers/random_stream_sampler.hpp"
#include "twincal/samplers/sampler.hpp"
#include "twincal/samplers/sobol.hpp"
#include "twincal/samplers/sobol_direction_numbers.hpp"
