#pragma once
/// @file
/// L2-type discrepancies of a point set in [0, 1]^d (points as the columns of a d × n matrix),
/// in Hickernell's closed forms (Hickernell 1998, "A generalized discrepancy and quadrature
/// error bound"; Zhou, Fang & Ning 2013 for the mixture discrepancy). Each function returns the
/// squared discrepancy D², computed in O(n² d) with the pair sum over i < j:
///
///   centred:      CD² = (13/12)^d − (2/n) Σ_i Π_k (1 + ½|z_ik| − ½ z_ik²)
///                       + (1/n²) Σ_ij Π_k (1 + ½|z_ik| + ½|z_jk| − ½|x_ik − x_jk|),  z = x − ½
///   wrap-around:  WD² = −(4/3)^d + (1/n²) Σ_ij Π_k (3/2 − |x_ik − x_jk| (1 − |x_ik − x_jk|))
///   mixture:      MD² = (19/12)^d − (2/n) Σ_i Π_k (5/3 − ¼|z_ik| − ¼ z_ik²)
///                       + (1/n²) Σ_ij Π_k (15/8 − ¼|z_ik| − ¼|z_jk| − ¾|x_ik − x_jk|
///                                           + ½ |x_ik − x_jk|²)
///   L2-star:      L2*² = 3^-d − (2^(1−d)/n) Σ_i Π_k (1 − x_ik²)
///                        + (1/n²) Σ_ij Π_k (1 − max(x_ik, x_jk))
///
/// Conventions: SciPy's `qmc.discrepancy` returns CD², WD² and MD² but the root L2* for
/// "L2-star"; the tests compare accordingly.

#include <string_view>

#include <Eigen/Core>

#include "twincal/core/eigen.hpp"

namespace twincal {

enum class DiscrepancyKind {
  centered,     ///< CD, invariant under reflections about ½ in any coordinate
  wrap_around,  ///< WD, invariant under shifts modulo 1
  mixture,      ///< MD, Zhou, Fang & Ning's mixture of CD and WD
  l2_star,      ///< L2*, anchored at the origin (Warnock's formula)
};

[[nodiscard]] constexpr std::string_view to_string(DiscrepancyKind kind) noexcept {
  switch (kind) {
    case DiscrepancyKind::centered:
      return "centered";
    case DiscrepancyKind::wrap_around:
      return "wrap_around";
    case DiscrepancyKind::mixture:
      return "mixture";
    case DiscrepancyKind::l2_star:
      return "l2_star";
  }
  return "unknown";
}

/// Squared discrepancy D² of the columns of `points` (d × n, entries in [0, 1]). Throws
/// InvalidArgumentError for an empty set, NonFiniteError for a non-finite entry and
/// InvalidArgumentError for an entry outside [0, 1], naming the entry.
[[nodiscard]] double squared_discrepancy(const Eigen::Ref<const MatrixX>& points,
                                         DiscrepancyKind kind);

}  // namespace twincal
