#include "twincal/samplers/discrepancy.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "twincal/core/error.hpp"
#include "twincal/core/validate.hpp"

namespace twincal {
namespace {

// D² = constant + (single / n) Σ_i Π_k f(x_ik) + (1/n²) Σ_ij Π_k g(x_ik, x_jk), with the pair
// sum taken once over i < j and once over the diagonal.
template <typename Single, typename Pair>
double l2_discrepancy(const Eigen::Ref<const MatrixX>& x, double constant, double single_weight,
                      Single single, Pair pair) {
  const Index d = x.rows();
  const Index n = x.cols();
  double single_sum = 0.0;
  double diagonal = 0.0;
  double off_diagonal = 0.0;
  for (Index i = 0; i < n; ++i) {
    double f = 1.0;
    double g = 1.0;
    for (Index k = 0; k < d; ++k) {
      f *= single(x(k, i));
      g *= pair(x(k, i), x(k, i));
    }
    single_sum += f;
    diagonal += g;
    for (Index j = i + 1; j < n; ++j) {
      double h = 1.0;
      for (Index k = 0; k < d; ++k) h *= pair(x(k, i), x(k, j));
      off_diagonal += h;
    }
  }
  const auto count = static_cast<double>(n);
  return constant + single_weight / count * single_sum +
         (diagonal + 2.0 * off_diagonal) / (count * count);
}

void require_unit_cube(const Eigen::Ref<const MatrixX>& points) {
  if (points.cols() == 0 || points.rows() == 0) {
    throw InvalidArgumentError(
        "points", fmt::format("points: is {}x{}; rule: needs at least one point of dimension >= 1",
                              points.rows(), points.cols()));
  }
  require_finite("points", points);
  for (Index c = 0; c < points.cols(); ++c) {
    for (Index r = 0; r < points.rows(); ++r) {
      const double x = points(r, c);
      if (x >= 0.0 && x <= 1.0) continue;
      throw InvalidArgumentError(
          "points", fmt::format("points: entry ({}, {}) is {}; rule: must lie in [0, 1]", r, c, x));
    }
  }
}

}  // namespace

double squared_discrepancy(const Eigen::Ref<const MatrixX>& points, DiscrepancyKind kind) {
  require_unit_cube(points);
  const double d = static_cast<double>(points.rows());
  switch (kind) {
    case DiscrepancyKind::centered:
      return l2_discrepancy(
          points, std::pow(13.0 / 12.0, d), -2.0,
          [](double x) {
            const double z = std::abs(x - 0.5);
            return 1.0 + 0.5 * z - 0.5 * z * z;
          },
          [](double x, double y) {
            return 1.0 + 0.5 * std::abs(x - 0.5) + 0.5 * std::abs(y - 0.5) - 0.5 * std::abs(x - y);
          });
    case DiscrepancyKind::wrap_around:
      return l2_discrepancy(
          points, -std::pow(4.0 / 3.0, d), 0.0, [](double) { return 1.0; },
          [](double x, double y) {
            const double t = std::abs(x - y);
            return 1.5 - t * (1.0 - t);
          });
    case DiscrepancyKind::mixture:
      return l2_discrepancy(
          points, std::pow(19.0 / 12.0, d), -2.0,
          [](double x) {
            const double z = std::abs(x - 0.5);
            return 5.0 / 3.0 - 0.25 * z - 0.25 * z * z;
          },
          [](double x, double y) {
            const double t = std::abs(x - y);
            return 15.0 / 8.0 - 0.25 * std::abs(x - 0.5) - 0.25 * std::abs(y - 0.5) - 0.75 * t +
                   0.5 * t * t;
          });
    case DiscrepancyKind::l2_star:
      return l2_discrepancy(
          points, std::pow(3.0, -d), -std::pow(2.0, 1.0 - d), [](double x) { return 1.0 - x * x; },
          [](double x, double y) { return 1.0 - std::max(x, y); });
  }
  throw InvalidArgumentError("kind", fmt::format("kind: value is {}; rule: must be a "
                                                 "DiscrepancyKind enumerator",
                                                 static_cast<int>(kind)));
}

}  // namespace twincal
