#pragma once
/// @file
/// The whole core module.

#include "twincal/core/bounded_least_squares.hpp"
#include "twincal/core/cholesky.hpp"
#include "twincal/core/cholesky_factor.hpp"
#include "twincal/core/eigen.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/evaluation_counter.hpp"
#include "twincal/core/fixed_size_dispatch.hpp"
#include "twincal/core/format.hpp"
#include "twincal/core/gaussian.hpp"
#include "twincal/core/json_nesting.hpp"
#include "twincal/core/median.hpp"
#include "twincal/core/name_table.hpp"
#include "twincal/core/named_enum.hpp"
#include "twincal/core/options.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/core/stopwatch.hpp"
#include "twincal/core/symmetrize.hpp"
#include "twincal/core/validate.hpp"
