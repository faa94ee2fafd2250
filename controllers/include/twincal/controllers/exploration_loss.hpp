#pragma once
/// @file
/// The `ExplorationLoss` concept: a score of the posterior covariance P⁺(u) that the filter would
/// have after measuring at candidate u (smaller = more informative measurement). The paper's is
/// TraceLoss, eq. (12); Sec. 4 proposes WeightedTraceLoss; LogDetLoss (D-optimal) and
/// MaxEigenvalueLoss (E-optimal) are the classic alternatives of optimal experimental design.
///
/// twincal's losses share one scale: for an isotropic P⁺ = σ²I in d dimensions each equals
/// σ/√d, the paper's (1/d)·sqrt(tr P⁺), so swapping the loss in an ablation does not silently
/// rescale w in eq. (13).

#include <concepts>

#include "twincal/core/eigen.hpp"

namespace twincal {

template <typename L, int N>
concept ExplorationLoss = requires(const L& loss, const SquareMatrix<N>& posterior_covariance) {
  { loss(posterior_covariance) } -> std::convertible_to<double>;
};

}  // namespace twincal
