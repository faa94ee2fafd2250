#pragma once
/// @file
/// `write_symmetric_pairs`: the points x ± s·L_k (k = 1..n) that the symmetric third-degree
/// schemes share (Merwe's and Julier's unscented points after their centre, the CKF's cubature
/// points), at compile-time size up to `max_fixed_dispatch_size` (fixed_size_kernels.hpp).

#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/fixed_size_dispatch.hpp"
#include "twincal/filters/fixed_size_kernels.hpp"

namespace twincal {

/// Column first + k of `points` becomes mean + scale·L_k and column first + n + k becomes
/// mean − scale·L_k, for the columns L_k of `lower` (k = 0 … n − 1). At run-time sizes the
/// operands are bound to Eigen::Ref: a plain vector and matrices (what the filters pass) cost
/// nothing, an expression is evaluated into a temporary first.
template <typename Mean, typename Lower, typename Points>
void write_symmetric_pairs(const Eigen::MatrixBase<Mean>& mean,
                           const Eigen::MatrixBase<Lower>& lower, double scale, Index first,
                           Eigen::MatrixBase<Points>& points) {
  constexpr int n_at_compile_time = Points::RowsAtCompileTime;
  if constexpr (n_at_compile_time == Dynamic) {
    if (kernels::symmetric_pairs(mean, lower, scale, first, points.derived())) return;
  } else if constexpr (n_at_compile_time <= max_fixed_dispatch_size) {
    kernels::symmetric_pairs<n_at_compile_time>(mean, lower, scale, first, points);
    return;
  }
  const Index n = mean.size();
  for (Index k = 0; k < n; ++k) {
    points.col(first + k) = mean + scale * lower.col(k);
    points.col(first + n + k) = mean - scale * lower.col(k);
  }
}

}  // namespace twincal
