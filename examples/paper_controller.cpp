// The paper's w-controller (eqs. 11–14) on an analytic twin with three drifting locators,
// tracking the bouncing drift of eq. (15) over one episode of 100 assemblies.
#include <fmt/format.h>

#include "twincal/controllers/presets.hpp"
#include "twincal/models/bouncing_drift.hpp"
#include "twincal/models/rms_quadratic_twin.hpp"

int main() {
  using namespace twincal;
  RandomStream seed(2023);
  const RmsQuadraticTwin twin = RmsQuadraticTwin::generate({}, seed.substream("twin"));
  auto controller = make_paper_controller<3>(twin, seed.substream("controller"), {.w = 1.0});
  RandomStream drift_stream = seed.substream("drift");
  BouncingDrift<3> drift = BouncingDrift<3>::random(3, drift_stream);  // δu*_t, eq. (15)
  double relative_residual = 0.0;
  for (const AssemblyId& x : twin.assemblies()) {
    drift.advance();
    const Vector<3> u = controller.propose(x);
    const double z = twin.quality(x, Vector<3>(u - drift.offset()));  // the plant
    controller.observe(x, u, z);
    relative_residual += (z - twin.optimal_quality(x)) / twin.optimal_quality(x) / 100.0;
  }
  fmt::print("mean (z - z*)/z* = {:.4f}, final |est - true| = {:.4f}\n", relative_residual,
             (controller.offset_estimate() - drift.offset()).norm());
}
