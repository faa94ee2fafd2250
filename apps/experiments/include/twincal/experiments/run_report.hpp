#pragma once
/// @file
/// `RunReport`: what run_experiments did — episodes planned, skipped (already stored) and run.

#include "twincal/core/eigen.hpp"

namespace twincal {

struct RunReport {
  Index planned = 0;    ///< episodes in the study
  Index skipped = 0;    ///< already in the results
  Index completed = 0;  ///< run now
  double seconds = 0.0;
};

}  // namespace twincal
