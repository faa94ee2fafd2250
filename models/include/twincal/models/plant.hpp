#pragma once
/// @file
/// `Plant<T, D>`: the simulated production cell that a controller is run against: the twin with
/// the true, drifting locator offset δu*_t (Assumption 1, eq. 4) and measurement noise, eq. (5b):
///   z_t = Q(x_t, u_t − δu*_t) + v_t,   v_t ~ N(0, σz²),
/// after which the drift scenario moves to δu*_{t+1}. The paper's experiments measure without
/// noise (σz² = 0 is allowed) while the filter still assumes σz² > 0.

#include <cmath>
#include <utility>

#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/core/validate.hpp"
#include "twincal/models/drift.hpp"
#include "twincal/models/twin.hpp"

namespace twincal {

template <Twin T, Drift D>
class Plant {
 public:
  using Assembly = typename T::Assembly;

  /// @throws DimensionMismatchError when the drift's dimension is not the twin's d;
  ///         NonFiniteError / InvalidArgumentError for a negative or non-finite variance.
  Plant(const T& twin, D drift, double noise_variance, RandomStream stream)
      : twin_(&twin),
        drift_(std::move(drift)),
        noise_sd_(std::sqrt(noise_variance)),
        stream_(std::move(stream)) {
    require_dimension("drift.dimension()", drift_.dimension(), twin.control_dimension());
    require_finite("noise_variance", noise_variance);
    require_non_negative("noise_variance", noise_variance);
  }

  [[nodiscard]] const T& twin() const noexcept { return *twin_; }
  [[nodiscard]] const D& drift() const noexcept { return drift_; }
  /// t: the number of assemblies produced so far.
  [[nodiscard]] Index time() const { return drift_.time(); }
  /// δu*_t, the offset the next assembly is produced with.
  [[nodiscard]] decltype(auto) offset() const { return drift_.offset(); }

  /// Q(x, u − δu*_t): the quality the next assembly would have, without noise.
  [[nodiscard]] double noiseless_quality(const Assembly& assembly,
                                         const Eigen::Ref<const VectorX>& control) const {
    require_control(control, twin_->control_dimension());
    const VectorX shifted = control - drift_.offset();
    return twin_->quality(assembly, shifted);
  }

  /// Produces assembly x_t with control u_t and returns its measured quality z_t; then advances
  /// the drift to t + 1. On an exception (bad control, failing twin) nothing changes.
  [[nodiscard]] double produce(const Assembly& assembly, const Eigen::Ref<const VectorX>& control) {
    const double quality = noiseless_quality(assembly, control);
    const double z = noise_sd_ > 0.0 ? quality + noise_sd_ * stream_.normal() : quality;
    drift_.advance();
    return z;
  }

 private:
  const T* twin_;
  D drift_;
  double noise_sd_;
  RandomStream stream_;
};

}  // namespace twincal
