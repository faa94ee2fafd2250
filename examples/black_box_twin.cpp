// The active controller on twins whose Q² is not a quadratic — contact, stiffening, kinks
// (models/key_point_twin.hpp) — with and without weighing each assembly by its model's error
// (ActiveOptions::weigh_model_error; without it, an assembly whose model fails its check goes to
// a random-walk sigma-point filter). Paper's protocol: 100 assemblies, the bouncing drift of
// eq. (15) on every locator; prints the median over the runs of the mean relative residual
// (z − z*)/z* for no calibration and for both settings, and how many runs lost the offset (their
// estimate further from δu* than no estimate, over the second half).
//
//   black_box_twin [runs] [dimension] [strength] [seed]
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "black_box_episode.hpp"
#include "twincal/controllers/presets.hpp"
#include "twincal/controllers/searched_optimum_twin.hpp"
#include "twincal/models/contact_nonlinearity.hpp"
#include "twincal/models/key_point_twin.hpp"
#include "twincal/models/kink_nonlinearity.hpp"
#include "twincal/models/stiffening_nonlinearity.hpp"

namespace {

using namespace twincal;
using examples::median;

struct Outcome {
  double relative_residual = 0.0;
  bool lost = false;
};

// One episode; `options` unset runs no calibration (u0 − δu* reaches the plant).
template <typename T>
Outcome run_episode(const T& twin, const RandomStream& run,
                    const std::optional<ActiveOptions>& options) {
  std::optional<ActiveController<T>> controller;
  if (options) controller.emplace(twin, run.substream("controller"), *options);
  Outcome outcome;
  outcome.lost = examples::drifting_episode(
      twin, run,
      [&](const AssemblyId& x, const VectorX& offset) {
        const VectorX u = controller ? VectorX(controller->propose(x)) : twin.optimum(x);
        const double z = twin.quality(x, VectorX(u - offset));
        if (controller) controller->observe(x, u, z);
        outcome.relative_residual += (z - twin.optimal_quality(x)) / twin.optimal_quality(x);
      },
      [&] {
        return controller ? VectorX(controller->offset_estimate())
                          : VectorX::Zero(twin.control_dimension());
      });
  outcome.relative_residual /= static_cast<double>(twin.assemblies().size());
  return outcome;
}

template <typename Kind>
void compare(int runs, Index d, double strength, std::uint64_t seed) {
  KeyPointTwinOptions options;
  options.assemblies.dimension = d;
  options.strength = strength;
  KeyPointTwin<Kind> key_points(options, RandomStream(seed).substream("twin"));
  const std::vector<AssemblyId> assemblies = key_points.assemblies();
  // Q² is not a quadratic: u0 and z* are searched (NLopt), as for a real twin.
  const SearchedOptimumTwin<KeyPointTwin<Kind>> twin(std::move(key_points), assemblies);
  const std::vector<std::optional<ActiveOptions>> settings{
      std::nullopt, ActiveOptions{.weigh_model_error = true},
      ActiveOptions{.weigh_model_error = false}};
  std::string line = fmt::format("{:<11}", Kind::name());
  for (const std::optional<ActiveOptions>& setting : settings) {
    std::vector<double> residuals;
    int lost = 0;
    for (int r = 0; r < runs; ++r) {
      const RandomStream run =
          RandomStream(seed).substream("run").substream(static_cast<std::uint64_t>(r));
      const Outcome outcome = run_episode(twin, run, setting);
      residuals.push_back(outcome.relative_residual);
      lost += outcome.lost ? 1 : 0;
    }
    line += fmt::format("  {:>8.4f} ({}/{} lost)", median(residuals), lost, runs);
  }
  fmt::print("{}\n", line);
}

}  // namespace

int main(int argc, char** argv) {
  const int runs = argc > 1 ? std::atoi(argv[1]) : 5;
  const Index d = argc > 2 ? std::atol(argv[2]) : 3;
  const double strength = argc > 3 ? std::atof(argv[3]) : 1.0;
  const std::uint64_t seed = argc > 4 ? std::strtoull(argv[4], nullptr, 10) : 2023;
  if (runs < 1 || d < 1 || !(strength >= 0.0 && strength <= 1.0)) {
    fmt::print(stderr,
               "usage: black_box_twin [runs >= 1] [dimension >= 1] [strength in [0, 1]] "
               "[seed]\n");
    return 2;
  }
  fmt::print("d = {}, strength {}, {} runs of 100 assemblies, seed {}: median (z - z*)/z*\n", d,
             strength, runs, seed);
  fmt::print("{:<11}  {:>20}  {:>20}  {:>20}\n", "twin", "no calibration", "active",
             "active, no weighing");
  compare<ContactNonlinearity>(runs, d, strength, seed);
  compare<StiffeningNonlinearity>(runs, d, strength, seed);
  compare<KinkNonlinearity>(runs, d, strength, seed);
  return 0;
}
