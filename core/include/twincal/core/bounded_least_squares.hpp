#pragma once
/// @file
/// `bounded_least_squares`: min ‖y0 + B u‖² over lower ≤ u ≤ upper — the individual optimum
/// u0 = argmin_u Q(x, u) of eq. (3) for an affine twin inside the locators' box.

#include <Eigen/Core>

#include "twincal/core/eigen.hpp"

namespace twincal {

/// What the solver returns: the minimizer and how many active-set passes it took.
struct BoundedLeastSquaresSummary {
  VectorX solution;
  Index passes = 0;  ///< least-squares solves on the free variables
};

/// Primal active-set method: solve the least-squares problem on the free variables with the
/// others at their bounds; step back to the box when that leaves it (fixing the blocking
/// variable), otherwise free the fixed variable whose gradient says it wants to move inwards,
/// until none does (the KKT conditions). Starts at u = 0, which must lie in the box. Rank-
/// deficient B is fine: each free solve is the minimum-norm one.
/// @throws DimensionMismatchError when y0 has not B.rows() entries or a bound not B.cols();
///         NonFiniteError naming the argument with a non-finite entry; InvalidArgumentError when
///         0 is not inside [lower, upper]; Error when the KKT conditions are not reached in
///         50 (d + 1) passes.
[[nodiscard]] BoundedLeastSquaresSummary bounded_least_squares(
    const Eigen::Ref<const MatrixX>& b, const Eigen::Ref<const VectorX>& y0,
    const Eigen::Ref<const VectorX>& lower, const Eigen::Ref<const VectorX>& upper);

}  // namespace twincal
