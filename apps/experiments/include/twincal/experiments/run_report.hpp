#pragma once
/// @file
/// `RunReport`: what run_experiments did — episodes planned, left to other shards, skipped
/// (already stored) and run.

#include "twincal/core/eigen.hpp"

namespace twincal {

struct RunReport {
  Index planned = 0;           ///< episodes in the study
  Index in_other_shards = 0;   ///< planned, but another shard's (StudyShard)
  Index skipped = 0;           ///< this shard's, already in the results
  Index completed = 0;         ///< run now
  double seconds = 0.0;        ///< wall time of the whole run
  double setup_seconds = 0.0;  ///< of it, building the twins (u0(x), z*(x) searches)
};

}  // namespace twincal
