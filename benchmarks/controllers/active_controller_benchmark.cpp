// Time per assembly (one propose + observe) of the active controller (docs/controllers.md) over the
// control dimension d = 3, 12, 19, 32, with the Q-evaluations per assembly it spends (its budget is
// 4(d + 1)²): the cost a user pays to calibrate every locator at once. Same episodes and twin as
// the w-controller's benchmark (episode_benchmark.hpp), so the two tables compare directly.
#include <benchmark/benchmark.h>

#include "episode_benchmark.hpp"
#include "twincal/controllers/presets.hpp"
#include "twincal/controllers/searched_optimum_twin.hpp"
#include "twincal/models/contact_nonlinearity.hpp"
#include "twincal/models/key_point_twin.hpp"

namespace {

using namespace twincal;
using namespace twincal::benchmarks;

template <int N>
void BM_ActiveController(benchmark::State& state) {
  const Index d =
      run_rms_quadratic_episodes<N>(state, [](const CountedTwin& counted, std::uint64_t episode) {
        return ActiveController<CountedTwin, N>(counted, RandomStream(3).substream(episode));
      });
  state.counters["budget"] = static_cast<double>(4 * (d + 1) * (d + 1));
}

// The same on a twin whose Q² is not a quadratic (key points with contact, strength 1): every
// assembly refits H, and the history's models are refitted where the fit uses them — the cost of
// a black-box twin, in time and in evaluations.
using ContactTwin = SearchedOptimumTwin<KeyPointTwin<ContactNonlinearity>>;
void BM_ActiveControllerOnContact(benchmark::State& state) {
  const auto d = static_cast<Index>(state.range(0));
  KeyPointTwinOptions options;
  options.assemblies.dimension = d;
  KeyPointTwin<ContactNonlinearity> key_points(options, RandomStream(11));
  const std::vector<AssemblyId> assemblies = key_points.assemblies();
  const ContactTwin twin(std::move(key_points), assemblies);
  const Evaluator<ContactTwin> counted(twin);
  run_episodes<Dynamic>(state, twin, counted, [&](std::uint64_t episode) {
    return ActiveController<Evaluator<ContactTwin>>(counted, RandomStream(3).substream(episode));
  });
  state.counters["budget"] = static_cast<double>(4 * (d + 1) * (d + 1));
}

}  // namespace

BENCHMARK(BM_ActiveControllerOnContact)->Arg(3)->Arg(12)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_ActiveController<Dynamic>)
    ->Arg(3)
    ->Arg(12)
    ->Arg(19)
    ->Arg(32)
    ->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_ActiveController<3>)->Unit(benchmark::kMicrosecond);
