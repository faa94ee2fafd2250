#pragma once
/// @file
/// `quadratic_departure`: how far a twin's Q²(x, ·) is from a quadratic around a control — the
/// root-mean-square residual of the best quadratic fit of Q² over a cube around u, relative to
/// Q²'s standard deviation there. 0 for a twin whose Q² is quadratic (the FEM twins, the
/// RMS-quadratic twin); a controller that models Q² as a quadratic (the active controller's
/// surrogate) sees model errors of about this fraction of what the control changes.

#include <cmath>
#include <optional>
#include <string>

#include <fmt/format.h>
#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/options.hpp"
#include "twincal/core/qr.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/core/validate.hpp"
#include "twincal/models/twin.hpp"

namespace twincal {

struct QuadraticDepartureOptions {
  /// The cube's half width per locator, as a fraction of the twin's box width there.
  double half_width_fraction = 0.25;
  /// Sample points per coefficient of the quadratic, (d + 1)(d + 2)/2 coefficients.
  Index points_per_coefficient = 10;

  [[nodiscard]] std::optional<std::string> validate() const {
    return first_problem({rule::positive_finite("half_width_fraction", half_width_fraction),
                          rule::at_least("points_per_coefficient", points_per_coefficient,
                                         decltype(points_per_coefficient){2})});
  }
};

/// The departure of Q²(x, ·) from a quadratic over the cube center ± half_width_fraction · box
/// width, sampled uniformly from `stream` in one twin batch of points_per_coefficient ·
/// (d + 1)(d + 2)/2 controls. Returns 0 when Q² is constant over the cube.
/// @throws InvalidArgumentError (options), DimensionMismatchError (center), NonFiniteError when
///         the twin returns a non-finite quality; the twin's own errors propagate.
template <Twin T>
[[nodiscard]] double quadratic_departure(const T& twin, const typename T::Assembly& assembly,
                                         const Eigen::Ref<const VectorX>& center,
                                         RandomStream stream,
                                         const QuadraticDepartureOptions& options = {}) {
  require_valid("options", options);
  const Index d = twin.control_dimension();
  require_dimension("center", center.size(), d);
  require_finite("center", center);
  const Index coefficients = (d + 1) * (d + 2) / 2;
  const Index count = options.points_per_coefficient * coefficients;
  const VectorX half_width =
      options.half_width_fraction * (twin.upper_bounds() - twin.lower_bounds());
  MatrixX points(d, count);
  for (double& p : points.reshaped()) p = 2.0 * stream.uniform() - 1.0;
  MatrixX design(count, coefficients);  // [1, e_i, e_i e_j (i <= j)] in cube units
  for (Index c = 0; c < count; ++c) {
    Index column = 0;
    design(c, column++) = 1.0;
    for (Index i = 0; i < d; ++i) design(c, column++) = points(i, c);
    for (Index i = 0; i < d; ++i) {
      for (Index j = i; j < d; ++j) design(c, column++) = points(i, c) * points(j, c);
    }
  }
  const MatrixX controls = (half_width.asDiagonal() * points).colwise() + center;
  VectorX squares(count);
  twin.quality_batch(assembly, controls, squares);
  require_finite("twin quality", squares);
  squares = squares.array().square().matrix();
  const double mean = squares.mean();
  const double spread = std::sqrt((squares.array() - mean).square().mean());
  if (!(spread > 0.0)) return 0.0;
  const VectorX fit = design.colPivHouseholderQr().solve(squares);
  const VectorX residual = design * fit - squares;
  return std::sqrt(residual.squaredNorm() / static_cast<double>(count)) / spread;
}

}  // namespace twincal
