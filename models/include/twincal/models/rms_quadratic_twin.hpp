#pragma once
/// @file
/// `RmsQuadraticTwin`: an analytic twin with an exactly known optimum,
///   Q(x, u) = sqrt(q0(x) + (u − a(x))ᵀ H (u − a(x))),
/// the shape of an RMS deviation over measurement points that depends quadratically on the
/// locator adjustment (and the shape of the reference filter runs). H is symmetric positive
/// definite and shared by all assemblies; q0(x) and a(x) come from an AnalyticAssemblySet. The
/// optimum is u0(x) = a(x) (eq. 3) with z*(x) = sqrt(q0(x)).

#include <cmath>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/options.hpp"
#include "twincal/core/qr.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/core/validate.hpp"
#include "twincal/models/analytic_assembly_set.hpp"
#include "twincal/models/assembly_id.hpp"
#include "twincal/models/exact_optimum_twin.hpp"
#include "twincal/models/twin.hpp"

namespace twincal {

struct RmsQuadraticTwinOptions {
  AnalyticAssemblyOptions assemblies;
  double min_curvature = 0.5;  ///< smallest eigenvalue of H
  double max_curvature = 5.0;  ///< largest eigenvalue of H

  [[nodiscard]] std::optional<std::string> validate() const {
    return first_problem(
        {rule::nested("assemblies", assemblies),
         rule::positive_range("min_curvature", min_curvature, "max_curvature", max_curvature)});
  }
};

/// Q(x, u) = sqrt(q0(x) + (u − a(x))ᵀ H (u − a(x))): RmsQuadraticTwin's shape.
class RmsQuadraticShape {
 public:
  explicit RmsQuadraticShape(MatrixX curvature) : curvature_(std::move(curvature)) {}

  /// H.
  [[nodiscard]] const MatrixX& curvature() const noexcept { return curvature_; }

  // eᵀHe summed in place: no temporary, so a dynamic-size batch does not allocate per column.
  template <typename A, typename U>
  [[nodiscard]] double quality(double q0, const A& a, const U& control) const {
    const Index d = control.size();
    double quadratic = 0.0;
    for (Index l = 0; l < d; ++l) {
      const double e_l = control(l) - a(l);
      double row = 0.0;
      for (Index k = 0; k < d; ++k) row += curvature_(k, l) * (control(k) - a(k));
      quadratic += e_l * row;
    }
    return std::sqrt(q0 + quadratic);
  }

 private:
  MatrixX curvature_;
};

/// The RMS-quadratic twin (see the file comment): an ExactOptimumTwin, Q(x, u), the batch and
/// the optimum u0(x) = a(x) (eq. 3) with z*(x) = sqrt(q0(x)) included; this class adds H.
class RmsQuadraticTwin : public ExactOptimumTwin<RmsQuadraticShape> {
 public:
  /// A twin over `assemblies` with the given H.
  /// @throws DimensionMismatchError, NonFiniteError, InvalidArgumentError,
  ///         NotPositiveDefiniteError when H is not d × d symmetric positive definite.
  RmsQuadraticTwin(AnalyticAssemblySet assemblies, MatrixX curvature)
      : ExactOptimumTwin(std::move(assemblies), RmsQuadraticShape(std::move(curvature))) {
    require_shape("curvature", this->curvature(), control_dimension(), control_dimension());
    require_positive_definite("curvature", this->curvature());
  }

  /// Draws the assemblies (substream "assemblies") and H = V diag(λ) Vᵀ with V a random
  /// orthogonal matrix and λ log-uniform in [min_curvature, max_curvature] (substream
  /// "curvature"), so H couples the locators.
  /// @throws InvalidArgumentError when the options are inconsistent.
  [[nodiscard]] static RmsQuadraticTwin generate(const RmsQuadraticTwinOptions& options,
                                                 const RandomStream& stream) {
    AnalyticAssemblySet assemblies = draw_assemblies(options, stream);
    const Index d = assemblies.dimension();
    RandomStream curvature_stream = stream.substream("curvature");
    MatrixX gaussian(d, d);
    curvature_stream.fill_normal(gaussian);
    const MatrixX rotation = Eigen::HouseholderQR<MatrixX>(gaussian).householderQ();
    VectorX eigenvalues(d);
    const double log_min = std::log(options.min_curvature);
    const double log_max = std::log(options.max_curvature);
    for (double& lambda : eigenvalues) {
      lambda = std::exp(log_min + (log_max - log_min) * curvature_stream.uniform());
    }
    MatrixX curvature = rotation * eigenvalues.asDiagonal() * rotation.transpose();
    curvature = 0.5 * (curvature + curvature.transpose()).eval();
    return {std::move(assemblies), std::move(curvature)};
  }

  /// H.
  [[nodiscard]] const MatrixX& curvature() const noexcept { return shape().curvature(); }
};

static_assert(TwinWithOptimum<RmsQuadraticTwin>);

}  // namespace twincal
