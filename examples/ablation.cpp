// One episode of the paper's protocol (100 assemblies, bouncing drift of eq. 15 on 3 locators,
// plant noise σz²) for the baseline, the default controller and the w-controller, then the
// w-controller with one policy swapped at a time: UKF→CKF, Sobol→Halton, trace→log-det.
// Every controller sees the same assemblies, drift and noise.
//
//   ablation [seed] [w]
#include <cmath>
#include <cstdint>
#include <string>

#include <fmt/format.h>

#include "twincal/controllers/individualized_controller.hpp"
#include "twincal/controllers/presets.hpp"
#include "twincal/models/bouncing_drift.hpp"
#include "twincal/models/rms_quadratic_twin.hpp"

namespace {

using namespace twincal;
constexpr int d = 3;

struct Outcome {
  double relative_residual = 0.0;  // mean (z_t − z*_t)/z*_t
  double estimation_error = 0.0;   // mean ‖δû_t − δu*_t‖ (NaN for controllers without one)
  int diverged_at = -1;            // first t with ‖δû_t − δu*_t‖ > 10
};

template <typename C>
Outcome run_episode(C& controller, const RmsQuadraticTwin& twin, const RandomStream& run) {
  RandomStream drift_stream = run.substream("drift");
  RandomStream noise = run.substream("noise");
  BouncingDrift<d> drift = BouncingDrift<d>::random(d, drift_stream);
  Outcome outcome;
  int t = 0;
  for (const AssemblyId& x : twin.assemblies()) {
    drift.advance();
    const Vector<d> u = controller.propose(x);
    const double z = twin.quality(x, Vector<d>(u - drift.offset())) + 1e-2 * noise.normal();
    controller.observe(x, u, z);
    outcome.relative_residual += (z - twin.optimal_quality(x)) / twin.optimal_quality(x) / 100.0;
    if constexpr (EstimatingController<C>) {
      const double error = (Vector<d>(controller.offset_estimate()) - drift.offset()).norm();
      outcome.estimation_error += error / 100.0;
      if (error > 10.0 && outcome.diverged_at < 0) outcome.diverged_at = t;
    } else {
      outcome.estimation_error = std::nan("");
    }
    ++t;
  }
  return outcome;
}

void print(const std::string& name, const Outcome& o) {
  fmt::print("  {:<32} {:>10.4f} {:>12.4f} {:>10}\n", name, o.relative_residual, o.estimation_error,
             o.diverged_at < 0 ? "-" : fmt::format("t={}", o.diverged_at));
}

}  // namespace

int main(int argc, char** argv) {
  const std::uint64_t seed = argc > 1 ? std::stoull(argv[1]) : 2023;
  const double w = argc > 2 ? std::stod(argv[2]) : 1.0;
  const RandomStream root(seed);
  const RmsQuadraticTwin twin = RmsQuadraticTwin::generate({}, root.substream("twin"));
  const RandomStream run = root.substream("run");
  const RandomStream controllers = root.substream("controllers");
  const LookaheadOptions options{.w = w};

  fmt::print("seed {}, d = {}, w = {}\n  {:<32} {:>10} {:>12} {:>10}\n", seed, d, w, "controller",
             "(z-z*)/z*", "|du^ - du*|", "diverged");
  IndividualizedController<RmsQuadraticTwin> baseline(twin);
  print("baseline (individualized)", run_episode(baseline, twin, run));
  PaperDefaultController<RmsQuadraticTwin, d> default_controller(
      make_paper_filter<d>(twin, controllers));
  print("default, eq. (9)", run_episode(default_controller, twin, run));
  auto paper = make_paper_controller<d>(twin, controllers, options);
  print("w-controller (UKF+Sobol+trace)", run_episode(paper, twin, run));

  const Sobol sobol(d, paper.sampler().options());
  CubatureController<RmsQuadraticTwin, d> ckf(make_cubature_filter<d>(twin, controllers), sobol,
                                              options);
  print("  CKF for UKF", run_episode(ckf, twin, run));
  HaltonController<RmsQuadraticTwin, d> halton(
      make_paper_filter<d>(twin, controllers),
      Halton(d, {.scramble = true, .seed = controllers.substream("halton").seed()}), options);
  print("  Halton for Sobol", run_episode(halton, twin, run));
  LogDetController<RmsQuadraticTwin, d> log_det(make_paper_filter<d>(twin, controllers), sobol,
                                                options);
  print("  log-det for trace", run_episode(log_det, twin, run));
}
