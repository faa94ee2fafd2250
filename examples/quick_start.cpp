// The README's example, kept compiling here: seeded streams, the offset model of eq. (5c),
// a Cholesky factor and the exploration loss of eq. (12).
#include <fmt/format.h>

#include "twincal/controllers/trace_loss.hpp"
#include "twincal/core/core.hpp"
#include "twincal/models/random_walk.hpp"

int main() {
  twincal::RandomStream noise = twincal::RandomStream(2023).substream("offset");
  const auto walk = twincal::RandomWalk<3>::isotropic(3, 1e-3);  // Σu = 1e-3·I
  const twincal::CholeskyFactor<3> sqrt_q = twincal::cholesky(walk.process_noise()).factor;
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();  // δu*_0
  for (int t = 0; t < 100; ++t) {
    Eigen::Vector3d z;
    noise.fill_normal(z);
    offset = walk.propagate(offset) + sqrt_q.lower() * z;  // δu*_{t+1} ~ N(δu*_t, Σu)
  }
  fmt::print("delta_u*_100 = {:.4f}, L_explore(100 Sigma_u) = {:.4f}\n", offset,
             twincal::TraceLoss{}(100.0 * walk.process_noise()));
}
