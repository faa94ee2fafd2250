#pragma once
/// @file
/// Options of SigmaPointFilter and SquareRootSigmaPointFilter: which sigma points the update
/// uses after a predict, and the numerical safeguards of the covariance update.

#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>

#include <fmt/format.h>

#include "twincal/core/cholesky.hpp"
#include "twincal/core/named_enum.hpp"

namespace twincal {

/// Which points the measurement update uses after `predict()`.
enum class SigmaPointRefresh {
  /// Draw new points from the prior (x⁻, P⁻), so they carry the process noise Q (filterpy's
  /// current UnscentedKalmanFilter). Costs one Cholesky factorization per predict.
  redraw,
  /// Reuse the propagated points f(χ_i): drawn from the previous posterior, they do not carry Q
  /// (filterpy 1.4.5's UKF, the release the paper most likely used, and filterpy's CKF).
  reuse_propagated,
};

/// The choices' spellings, for to_string and parse_enum (named_enum.hpp).
[[nodiscard]] constexpr auto name_table(std::type_identity<SigmaPointRefresh>) noexcept {
  return std::to_array<NameEntry<SigmaPointRefresh>>(
      {{SigmaPointRefresh::redraw, "redraw"},
       {SigmaPointRefresh::reuse_propagated, "reuse_propagated"}});
}

struct SigmaPointFilterOptions {
  SigmaPointRefresh refresh = SigmaPointRefresh::redraw;

  /// Replace P by (P + Pᵀ)/2 after each predict and update, removing the round-off asymmetry of
  /// P − K S Kᵀ. (Standard form only; a square-root factor is symmetric by construction.)
  bool symmetrize = true;

  /// Update P in Joseph form, P⁺ = (I − K Hᵀ) P (I − K Hᵀ)ᵀ + K R̃ Kᵀ with the statistically
  /// linearised H = P⁻¹ Pxz and R̃ = R + max(Pzz − Hᵀ P H, 0): equal to P − K S Kᵀ in exact
  /// arithmetic, but a sum of positive semi-definite terms in floating point. (Standard form
  /// only.)
  bool joseph_form = false;

  /// How the covariance factorizations (sigma points, posterior) repair a covariance that is
  /// not numerically positive definite; `none` throws NotPositiveDefiniteError. A repaired
  /// covariance replaces the filter's P, so that P and its sigma points agree.
  CholeskyOptions factorization{};

  /// The options filterpy's filters implement: no symmetrization, P − K S Kᵀ, no repair.
  [[nodiscard]] static SigmaPointFilterOptions filterpy(SigmaPointRefresh refresh) {
    SigmaPointFilterOptions options;
    options.refresh = refresh;
    options.symmetrize = false;
    options.joseph_form = false;
    return options;
  }

  [[nodiscard]] std::optional<std::string> validate() const {
    return first_problem(
        {rule::check(
             refresh == SigmaPointRefresh::redraw || refresh == SigmaPointRefresh::reuse_propagated,
             "refresh", static_cast<int>(refresh), "must be redraw or reuse_propagated"),
         rule::nested("factorization", factorization)});
  }
};

}  // namespace twincal
