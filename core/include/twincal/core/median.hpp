#pragma once
/// @file
/// The median of a ring buffer's kept values, for the running medians the active controller and
/// its estimator keep (the plant's regrets, the normalized innovations) without allocating.

#include <algorithm>
#include <cstddef>
#include <span>

#include "twincal/core/validate.hpp"

namespace twincal {

/// The median of the first `count` values of `values` (for an even count, the upper of the two
/// middle values), found by partially sorting a copy in `workspace`, which must hold at least
/// `count` values; `values` is not changed and nothing is allocated.
/// @throws InvalidArgumentError unless 1 <= count <= min(values.size(), workspace.size()).
[[nodiscard]] inline double median_of_first(std::span<const double> values, std::size_t count,
                                            std::span<double> workspace) {
  require_in_range("count", static_cast<double>(count), 1.0,
                   static_cast<double>(std::min(values.size(), workspace.size())));
  std::copy_n(values.begin(), count, workspace.begin());
  const auto middle = workspace.begin() + static_cast<std::ptrdiff_t>(count / 2);
  std::nth_element(workspace.begin(), middle,
                   workspace.begin() + static_cast<std::ptrdiff_t>(count));
  return *middle;
}

}  // namespace twincal
