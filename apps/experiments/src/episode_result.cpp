#include "twincal/experiments/episode_result.hpp"

#include <cmath>
#include <limits>

namespace twincal {

void assess_lost(EpisodeResult& result) {
  const Index first = result.steps / 2;
  const Index count = result.steps - first;
  const Index d = result.offset.rows();
  double errors = 0.0;
  double offsets = 0.0;
  for (Index t = first; t < result.steps; ++t) {
    // One scalar loop for both norms rather than Eigen's reductions, whose summation order may
    // depend on the operands' alignment: with δû_t = 0 (the baseline), e = −δu*_t exactly and
    // both sums see the same squares in the same order.
    double error_squared = 0.0;
    double offset_squared = 0.0;
    for (Index i = 0; i < d; ++i) {
      const double e = result.estimate(i, t) - result.offset(i, t);
      const double o = result.offset(i, t);
      error_squared += e * e;
      offset_squared += o * o;
    }
    errors += std::sqrt(error_squared);
    offsets += std::sqrt(offset_squared);
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  result.estimate_error_second_half = count > 0 ? errors / static_cast<double>(count) : nan;
  result.offset_norm_second_half = count > 0 ? offsets / static_cast<double>(count) : nan;
  // Strict, and false for NaN: equal means (the baseline) are not lost.
  result.lost = result.estimate_error_second_half > result.offset_norm_second_half;
}

}  // namespace twincal
