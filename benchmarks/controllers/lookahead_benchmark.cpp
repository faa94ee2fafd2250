// Time per assembly (propose + observe) of the w-controller and the default controller, and the
// Q-evaluations per assembly, over the control dimension d: with the paper's candidate count
// 2^(2+d) (d <= 12; at d = 19 it would be 2^21 candidates × 39 sigma points per assembly) and with
// a fixed budget of 64 candidates. Episodes of 100 assemblies as in the paper (a fresh controller
// and drift each episode, set-up not timed), on the cheap analytic RMS-quadratic twin, so the
// numbers measure twincal's own overhead around the Q-evaluations.
#include <cstdint>
#include <optional>
#include <vector>

#include <benchmark/benchmark.h>

#include "twincal/controllers/presets.hpp"
#include "twincal/models/bouncing_drift.hpp"
#include "twincal/models/evaluator.hpp"
#include "twincal/models/rms_quadratic_twin.hpp"

namespace {

using namespace twincal;
using CountedTwin = Evaluator<RmsQuadraticTwin>;
constexpr std::size_t episode_length = 100;

RmsQuadraticTwin make_twin(Index d) {
  RmsQuadraticTwinOptions options;
  options.assemblies.dimension = d;
  return RmsQuadraticTwin::generate(options, RandomStream(11));
}

// Runs assemblies in episodes; `make` builds a fresh controller for each episode.
template <int N, typename Make>
void run_episodes(benchmark::State& state, const RmsQuadraticTwin& twin, const CountedTwin& counted,
                  Make make) {
  const Index d = twin.control_dimension();
  const std::vector<AssemblyId> assemblies = twin.assemblies();
  std::optional<decltype(make(std::uint64_t{0}))> controller;
  std::optional<BouncingDrift<Dynamic>> drift;
  std::uint64_t episode = 0;
  std::size_t t = episode_length;
  double scored = 0.0;
  std::uint64_t evaluations = 0;
  for (auto _ : state) {
    if (t == episode_length) {
      state.PauseTiming();
      controller.emplace(make(episode));
      RandomStream drift_stream = RandomStream(5).substream(episode++);
      drift.emplace(BouncingDrift<Dynamic>::random(d, drift_stream));
      t = 0;
      state.ResumeTiming();
    }
    drift->advance();
    const AssemblyId& x = assemblies[t++];
    const EvaluationStats before = counted.stats();
    const Vector<N> u = controller->propose(x);
    const VectorX shifted = VectorX(u) - drift->offset();
    controller->observe(x, u, twin.quality(x, shifted));
    evaluations += (counted.stats() - before).evaluations;
    if constexpr (requires { controller->last_proposal().candidates_scored; }) {
      scored += static_cast<double>(controller->last_proposal().candidates_scored);
    }
  }
  const auto iterations = static_cast<double>(state.iterations());
  state.counters["d"] = static_cast<double>(d);
  state.counters["Q_evals_per_assembly"] = static_cast<double>(evaluations) / iterations;
  state.counters["scored_per_assembly"] = scored / iterations;
}

template <int N>
void BM_LookaheadController(benchmark::State& state) {
  const Index d = N == Dynamic ? static_cast<Index>(state.range(0)) : N;
  const RmsQuadraticTwin twin = make_twin(d);
  const CountedTwin counted(twin);
  LookaheadOptions options{.w = 0.5};
  if (state.range(1) > 0) options.candidates = state.range(1);
  run_episodes<N>(state, twin, counted, [&](std::uint64_t episode) {
    return make_paper_controller<N>(counted, RandomStream(3).substream(episode), options);
  });
  state.counters["budget"] = static_cast<double>(options.candidate_count(d));
}

template <int N>
void BM_DefaultController(benchmark::State& state) {
  const Index d = N == Dynamic ? static_cast<Index>(state.range(0)) : N;
  const RmsQuadraticTwin twin = make_twin(d);
  const CountedTwin counted(twin);
  run_episodes<N>(state, twin, counted, [&](std::uint64_t episode) {
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
