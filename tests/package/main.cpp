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

int main() {
  const twincal::RandomWalk<3> walk = twincal::RandomWalk<3>::isotropic(3, 1e-3);
  const twincal::CholeskyResult<3> factored = twincal::cholesky(walk.process_noise());
  const double loss = twincal::TraceLoss{}(factored.factor.covariance());
  const double expected = std::sqrt(3e-3) / 3.0;
  fmt::print("consumer: trace loss {:.6g} (expected {:.6g})\n", loss, expected);
  return std::abs(loss - expected) < 1e-12 ? 0 : 1;
}
