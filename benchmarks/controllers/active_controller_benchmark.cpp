// Time per assembly (one propose + observe) of the active controller (issue 12) over the control
// dimension d = 3, 12, 19, 32, with the Q-evaluations per assembly it spends (its budget is
// 4(d + 1)²): the cost a user pays to calibrate every locator at once. Same episodes and twin as
// the w-controller's benchmark (episode_benchmark.hpp), so the two tables compare directly.
#include <benchmark/benchmark.h>

#include "episode_benchmark.hpp"
#include "twincal/controllers/active_controller.hpp"

namespace {

using namespace twincal;
using namespace twincal::benchmarks;

template <int N>
void BM_ActiveController(benchmark::State& state) {
  const Index d = N == Dynamic ? static_cast<Index>(state.range(0)) : N;
  const RmsQuadraticTwin twin = make_twin(d);
  const CountedTwin counted(twin);
  run_episodes<N>(state, twin, counted, [&](std::uint64_t episode) {
    return ActiveController<CountedTwin, N>(counted, RandomStream(3).substream(episode));
  });
  state.counters["budget"] = static_cast<double>(4 * (d + 1) * (d + 1));
}

}  // namespace

BENCHMARK(BM_ActiveController<Dynamic>)
    ->Arg(3)
    ->Arg(12)
    ->Arg(19)
    ->Arg(32)
    ->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_ActiveController<3>)->Unit(benchmark::kMicrosecond);
