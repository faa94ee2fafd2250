#pragma once
/// @file
/// `ExpectedQuality`: the paper's exploitation loss, eq. (11),
/// L_exploit(u) = Σ_i W(s_i) Q(x_t, u − s_i; θ0): the expected next-assembly quality under the
/// filter's belief about the offset, by the filter's own quadrature (its sigma points and mean
/// weights).

#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/validate.hpp"

namespace twincal {

struct ExpectedQuality {
  /// Σ W_i q_i. @throws DimensionMismatchError when the sizes differ.
  [[nodiscard]] double operator()(const Eigen::Ref<const VectorX>& qualities,
                                  const Eigen::Ref<const VectorX>& mean_weights) const {
    require_dimension("qualities", qualities.size(), mean_weights.size());
    return mean_weights.dot(qualities);
  }
};

}  // namespace twincal
