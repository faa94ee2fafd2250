#pragma once
/// @file
/// Umbrella header of the models module: the twin concepts, the analytic twins and their
/// nonlinearities, state and measurement models, drifts, the plant, locator subsets, the evaluator
/// and its executions — what eq. (5) calls a model. (The conformance suite, testing/, is for tests
/// and is not included.)

#include "twincal/models/analytic_assembly_set.hpp"
#include "twincal/models/analytic_twin_base.hpp"
#include "twincal/models/assembly_id.hpp"
#include "twincal/models/bouncing_drift.hpp"
#include "twincal/models/brownian_drift.hpp"
#include "twincal/models/constant_drift.hpp"
#include "twincal/models/contact_nonlinearity.hpp"
#include "twincal/models/deviation_nonlinearity.hpp"
#include "twincal/models/drift.hpp"
#include "twincal/models/evaluation_error.hpp"
#include "twincal/models/evaluator.hpp"
#include "twincal/models/exact_optimum_twin.hpp"
#include "twincal/models/execution.hpp"
#include "twincal/models/kept_assemblies.hpp"
#include "twincal/models/key_point_twin.hpp"
#include "twincal/models/kink_nonlinearity.hpp"
#include "twincal/models/locator_subset.hpp"
#include "twincal/models/no_nonlinearity.hpp"
#include "twincal/models/parallel_execution.hpp"
#include "twincal/models/plant.hpp"
#include "twincal/models/quadratic_departure.hpp"
#include "twincal/models/quality_feedback.hpp"
#include "twincal/models/random_walk.hpp"
#include "twincal/models/rms_quadratic_twin.hpp"
#include "twincal/models/rugged_twin.hpp"
#include "twincal/models/step_drift.hpp"
#include "twincal/models/stiffening_nonlinearity.hpp"
#include "twincal/models/twin.hpp"
