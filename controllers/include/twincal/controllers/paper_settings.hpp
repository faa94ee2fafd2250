#pragma once
/// @file
/// `PaperSettings`: the paper's filter settings (Sec. 2.4), the one place their defaults are
/// written; the presets, the experiments' config, the active controller and the Python
/// bindings take theirs from here.

#include <optional>
#include <string>

#include "twincal/core/options.hpp"

namespace twincal {

/// The paper's numbers (Sec. 2.4). The paper does not state the UKF's α, β, κ (it used
/// filterpy, which requires them); α = 1, β = 2, κ = 0 put the points at ±sqrt(d)·σ with
/// non-negative weights, which keeps P⁻ positive definite for every d.
struct PaperSettings {
  double process_variance = 1e-3;      ///< Σu = process_variance·I, eq. (5c)
  double measurement_variance = 1e-4;  ///< σz², eq. (5b): 1e-4 car body (door: below)
  double initial_variance = 1e-3;      ///< δû0 ~ N(0, initial_variance·I) and P0
  double alpha = 1.0;                  ///< Merwe scaled points
  double beta = 2.0;
  double kappa = 0.0;
  /// σz² of the car door, eq. (5b): its quality is about 100 times smaller than the body's.
  static constexpr double door_measurement_variance = 1e-6;

  [[nodiscard]] std::optional<std::string> validate() const {
    return first_problem({rule::positive_finite("process_variance", process_variance),
                          rule::positive_finite("measurement_variance", measurement_variance),
                          rule::positive_finite("initial_variance", initial_variance),
                          rule::positive_finite("alpha", alpha)});
  }
};

}  // namespace twincal
