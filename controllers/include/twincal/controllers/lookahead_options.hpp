#pragma once
/// @file
/// `LookaheadOptions`: the settings of the w-controller, eqs. (13)–(14), with the paper's values
/// as defaults (Sec. 2.4): w ∈ [0, 1], U_t of half-width 0.1 around u0 + δû, 2^(2+d) candidates.

#include <cmath>
#include <optional>
#include <string>

#include <fmt/format.h>

#include "twincal/core/eigen.hpp"
#include "twincal/core/options.hpp"
#include "twincal/samplers/gaussian_transform.hpp"

namespace twincal {

struct LookaheadOptions {
  /// Weight of exploration in L_w = (1 − w)·exploit + w·explore, eq. (13).
  double w = 0.5;
  /// Half-width of the box U_t = {|u_i − û*_i| <= h} around the default control, eq. (14).
  double box_half_width = 0.1;
  /// Candidate budget per assembly; unset: the paper's 2^(2+d).
  std::optional<Index> candidates{};
  /// Draw further batches until `candidates` survive the box (the paper draws one batch).
  bool keep_drawing = false;
  /// Bound on the batches drawn with keep_drawing.
  Index max_batches = 16;
  /// How uniform points become N(û*, P) (factor, clipping of the inverse CDF).
  GaussianTransformOptions transform{};

  /// The candidate budget for a d-dimensional control.
  [[nodiscard]] Index candidate_count(Index d) const {
    return candidates.value_or(Index{1} << (2 + d));
  }

  [[nodiscard]] std::optional<std::string> validate() const {
    return first_problem({rule::in_closed("w", w, 0.0, 1.0),
                          rule::positive_finite("box_half_width", box_half_width),
                          rule::check(!candidates || *candidates >= 1, "candidates",
                                      candidates.value_or(0), "must be >= 1 (unset: 2^(2+d))"),
                          rule::at_least("max_batches", max_batches, Index{1}),
                          rule::nested("transform", transform)});
  }
};

}  // namespace twincal
