#include "twincal/core/bounded_least_squares.hpp"

#include <vector>

#include <fmt/format.h>
#include <Eigen/QR>

#include "twincal/core/error.hpp"
#include "twincal/core/validate.hpp"

namespace twincal {

namespace {

void require_arguments(const Eigen::Ref<const MatrixX>& b, const Eigen::Ref<const VectorX>& y0,
                       const Eigen::Ref<const VectorX>& lower,
                       const Eigen::Ref<const VectorX>& upper) {
  require_dimension("y0", y0.size(), b.rows());
  require_dimension("lower", lower.size(), b.cols());
  require_dimension("upper", upper.size(), b.cols());
  require_finite("B", b);
  require_finite("y0", y0);
  require_finite("lower", lower);
  require_finite("upper", upper);
  for (Index k = 0; k < b.cols(); ++k) {
    if (!(lower(k) <= 0.0 && 0.0 <= upper(k))) {
      throw InvalidArgumentError(
          "lower, upper",
          fmt::format("lower, upper: entry {} is [{}, {}]; rule: must contain 0 (the start)", k,
                      lower(k), upper(k)));
    }
  }
}

}  // namespace

BoundedLeastSquaresSummary bounded_least_squares(const Eigen::Ref<const MatrixX>& b,
                                                 const Eigen::Ref<const VectorX>& y0,
                                                 const Eigen::Ref<const VectorX>& lower,
                                                 const Eigen::Ref<const VectorX>& upper) {
  require_arguments(b, y0, lower, upper);
  const Index d = b.cols();
  VectorX u = VectorX::Zero(d);
  std::vector<int> state(static_cast<std::size_t>(d), 0);  // 0 free, −1 at lower, +1 at upper
  const auto at = [&](Index k) -> int& { return state[static_cast<std::size_t>(k)]; };
  // Each pass fixes or frees one variable; a few passes per variable suffice in practice.
  const Index passes = 50 * d + 50;
  for (Index pass = 0; pass < passes; ++pass) {
    std::vector<Index> free;
    for (Index k = 0; k < d; ++k) {
      if (at(k) == 0) free.push_back(k);
    }
    VectorX target = u;
    if (!free.empty()) {
      VectorX residual = y0;
      for (Index k = 0; k < d; ++k) {
        if (at(k) != 0) residual += b.col(k) * u(k);
      }
      MatrixX columns(b.rows(), static_cast<Index>(free.size()));
      for (std::size_t c = 0; c < free.size(); ++c)
        columns.col(static_cast<Index>(c)) = b.col(free[c]);
      const VectorX step =
          Eigen::CompleteOrthogonalDecomposition<MatrixX>(columns).solve(-residual);
      for (std::size_t c = 0; c < free.size(); ++c) target(free[c]) = step(static_cast<Index>(c));
    }
    double alpha = 1.0;
    Index blocking = -1;
    for (const Index k : free) {
      const double delta = target(k) - u(k);
      if (target(k) > upper(k) && delta > 0.0 && (upper(k) - u(k)) / delta < alpha) {
        alpha = (upper(k) - u(k)) / delta;
        blocking = k;
      } else if (target(k) < lower(k) && delta < 0.0 && (lower(k) - u(k)) / delta < alpha) {
        alpha = (lower(k) - u(k)) / delta;
        blocking = k;
      }
    }
    if (blocking >= 0) {
      u += alpha * (target - u);
      u(blocking) = target(blocking) > upper(blocking) ? upper(blocking) : lower(blocking);
      at(blocking) = target(blocking) > upper(blocking) ? 1 : -1;
      continue;
    }
    u = target;
    const VectorX gradient = b.transpose() * (y0 + b * u);
    Index release = -1;
    double worst = 0.0;
    for (Index k = 0; k < d; ++k) {
      // At the lower bound the objective must not decrease upwards (gradient ≥ 0), at the upper
      // bound not downwards (gradient ≤ 0).
      const double violation = at(k) == -1 ? -gradient(k) : at(k) == 1 ? gradient(k) : 0.0;
      if (violation > worst) {
        worst = violation;
        release = k;
      }
    }
    if (release < 0) return {std::move(u), pass + 1};
    at(release) = 0;
  }
  throw Error("optimum", fmt::format("optimum: the box-constrained least squares did not converge "
                                     "in {} active-set passes; rule: must reach the KKT conditions",
                                     passes));
}

}  // namespace twincal
