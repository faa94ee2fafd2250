#pragma once
/// @file
/// `ContactNonlinearity`: gaps that close. p = m / 6 contacts (drawn) each watch a key point i_j
/// that faces a neighbouring part across a gap g_j in a direction c_j = ±1. Once the adjustment
/// moves the point across its gap, the contact force pushes back — on that point and, through
/// the structure, on every other:
///   r ← r − s Σ_j k_j max(0, c_j (B e)_{i_j} − g_j),   k_j = c_j e_{i_j} + ν_j,  ν_j ~ N(0, ¾² I)
/// (s = strength ∈ [0, 1]: 1 stops the watched point rigidly), with B e how far the control moved
/// the key points from the twin's affine optimum (where every contact is open) and g_j uniform in
/// [0, ½√d] mm (a quarter box width of adjustment moves a point by about 0.4√d mm). The
/// deviations are piecewise affine in u and Q² piecewise quadratic, with kinks where a contact
/// closes: r − K relu(C r − g), the method of influence coefficients with contact (Dahlström &
/// Lindkvist 2007).

#include <algorithm>
#include <cmath>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/core/validate.hpp"
#include "twincal/models/deviation_nonlinearity.hpp"

namespace twincal {

class ContactNonlinearity {
 public:
  /// Draws the contacts (points, directions, gaps, force influences) for m key points from
  /// `stream`.
  /// @throws InvalidArgumentError unless 0 <= strength <= 1.
  ContactNonlinearity(Index key_points, Index dimension, double strength,
                      const RandomStream& stream)
      : points_(static_cast<std::size_t>(std::max<Index>(1, key_points / 6))),
        direction_(std::ssize(points_)),
        gap_(std::ssize(points_)),
        force_influence_(key_points, std::ssize(points_)) {
    RandomStream draws =
        nonlinearity_draws(stream, name(), strength, 1.0,
                           "must lie in [0, 1]: a contact stops that fraction of the penetration");
    const double max_gap = 0.5 * std::sqrt(static_cast<double>(dimension));
    draws.fill_normal(force_influence_);
    force_influence_ *= 0.75;
    for (Index j = 0; j < direction_.size(); ++j) {
      // Distinct points: the j-th of a draw without replacement.
      points_[static_cast<std::size_t>(j)] =
          (j * 6 + static_cast<Index>(6.0 * draws.uniform())) % key_points;
      direction_(j) = draws.uniform() < 0.5 ? 1.0 : -1.0;
      gap_(j) = max_gap * draws.uniform();
      force_influence_(points_[static_cast<std::size_t>(j)], j) = direction_(j);
    }
    force_influence_ *= strength;
  }

  static constexpr std::string_view name() { return "contact"; }

  void apply(const Eigen::Ref<const VectorX>& /*control*/,
             const Eigen::Ref<const VectorX>& /*error*/, const Eigen::Ref<const VectorX>& moved,
             Eigen::Ref<VectorX> deviations) const {
    for (Index j = 0; j < direction_.size(); ++j) {
      const double penetration =
          direction_(j) * moved(points_[static_cast<std::size_t>(j)]) - gap_(j);
      if (penetration > 0.0) deviations -= penetration * force_influence_.col(j);
    }
  }

 private:
  std::vector<Index> points_;  // i_j
  VectorX direction_;          // c_j
  VectorX gap_;                // g_j
  MatrixX force_influence_;    // s k_j, one column per contact
};

}  // namespace twincal
