// Uses one header of every module through the installed package and checks a result, so a
// missing header, target or dependency in the install fails this program.
#include <cmath>
#include <cstdio>

#include <fmt/format.h>

#include "twincal/controllers/trace_loss.hpp"
#include "twincal/core/core.hpp"
#include "twincal/filters/sigma_points.hpp"
#include "twincal/models/random_walk.hpp"
#include "twincal/samplers/sampler.hpp"
#include "twincal/samplers/sobol.hpp"

int main() {
  const twincal::RandomWalk<3> walk = twincal::RandomWalk<3>::isotropic(3, 1e-3);
  const twincal::CholeskyResult<3> factored = twincal::cholesky(walk.process_noise());
  const double loss = twincal::TraceLoss{}(factored.factor.covariance());
  const double expected = std::sqrt(3e-3) / 3.0;
  fmt::print("consumer: trace loss {:.6g} (expected {:.6g})\n", loss, expected);
  if (std::abs(loss - expected) >= 1e-12) return 1;

  // The compiled samplers library with its embedded direction-number table: point 3 of the
  // 21201-dimensional Sobol sequence has coordinates 1/4 or 3/4.
  twincal::Sobol sobol(21201);
  Eigen::MatrixXd points(21201, 4);
  sobol.fill(points);
  const bool quarters = (points.col(3).array() == 0.25 || points.col(3).array() == 0.75).all();
  fmt::print("consumer: Sobol point 3 in 21201 dimensions {}\n", quarters ? "ok" : "wrong");
  return quarters ? 0 : 1;
}
