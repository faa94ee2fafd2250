#pragma once
/// @file
/// `dispatch_fixed_size<MaxN>(n, kernel)`: runs a kernel written for a compile-time size K with
/// K equal to a run-time size n. Eigen unrolls and vectorizes fixed-size expressions; at the few
/// dimensions a filter usually has, the same arithmetic over run-time sizes costs 1.5–2× as much
/// in loop control and set-up. Each dispatching call site instantiates its kernel MaxN times, so
/// it belongs in compiled sources (or few headers), not in every template.

#include <utility>

#include "twincal/core/eigen.hpp"

namespace twincal {

/// The largest run-time size that twincal's run-time-sized kernels hand to a fixed-size
/// instantiation (the sizes most filters and twins have; beyond it the fixed-size code stops
/// paying for itself and its compile time).
inline constexpr int max_fixed_dispatch_size = 8;

/// Calls `kernel.template operator()<K>()` with K = n when 1 <= n <= MaxN and returns true;
/// returns false (calling nothing) otherwise.
template <int MaxN, typename Kernel>
bool dispatch_fixed_size(Index n, Kernel&& kernel) {
  return [&]<int... K>(std::integer_sequence<int, K...>) {
    return ((n == K + 1 && (kernel.template operator()<K + 1>(), true)) || ...);
  }
  (std::make_integer_sequence<int, MaxN>{});
}

}  // namespace twincal
