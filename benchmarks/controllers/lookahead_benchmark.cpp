// Time per assembly (propose + observe) of the w-controller and the default controller, and the
// Q-evaluations per assembly, over the control dimension d: with the paper's candidate count
// 2^(2+d) (d <= 12; at d = 19 it would be 2^21 candidates × 39 sigma points per assembly) and with
// a fixed budget of 64 candidates. Episodes of 100 assemblies as in the paper (a fresh controller
// and drift each episode, set-up not timed), on the cheap analytic RMS-quadratic twin, so the
// numbers measure twincal's own overhead around the Q-evaluations.
#include <benchmark/benchmark.h>

#include "episode_benchmark.hpp"
#include "twincal/controllers/presets.hpp"

namespace {

using namespace twincal;
using namespace twincal::benchmarks;

template <int N>
void BM_LookaheadController(benchmark::State& state) {
  LookaheadOptions options{.w = 0.5};
  if (state.range(1) > 0) options.candidates = state.range(1);
  const Index d =
      run_rms_quadratic_episodes<N>(state, [&](const CountedTwin& counted, std::uint64_t episode) {
        return make_paper_controller<N>(counted, RandomStream(3).substream(episode), options);
      });
  state.counters["budget"] = static_cast<double>(options.candidate_count(d));
}

template <int N>
void BM_DefaultController(benchmark::State& state) {
  run_rms_quadratic_episodes<N>(state, [](const CountedTwin& counted, std::uint64_t episode) {
    return PaperDefaultController<CountedTwin, N>(
        make_paper_filter<N>(counted, RandomStream(3).substream(episode)));
  });
}

// range(0) = d, range(1) = candidate budget (0: the paper's 2^(2+d)).
void paper_and_fixed_budgets(benchmark::internal::Benchmark* b) {
  for (const int d : {1, 2, 3, 6, 12}) b->Args({d, 0});
  for (const int d : {1, 2, 3, 6, 12, 19}) b->Args({d, 64});
}

}  // namespace

BENCHMARK(BM_LookaheadController<Dynamic>)
    ->Apply(paper_and_fixed_budgets)
    ->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_LookaheadController<3>)->Args({3, 0})->Args({3, 64})->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_DefaultController<Dynamic>)
    ->Arg(1)
    ->Arg(3)
    ->Arg(12)
    ->Arg(19)
    ->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_DefaultController<3>)->Unit(benchmark::kMicrosecond);
