// Includes every header of the installed package (the top-level umbrella) and checks a result
// of the header-only and of the compiled modules, so a missing header, target or dependency in
// the install, or a header that does not compile beside the others, fails this program.
#include <cmath>
#include <cstdio>

#include <fmt/format.h>

#include "twincal/twincal.hpp"

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
