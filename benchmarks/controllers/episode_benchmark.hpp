#pragma once
// Shared by the controller benchmarks: episodes of 100 assemblies as in the paper (a fresh
// controller and eq. (15) drift each episode, set-up not timed) on the cheap analytic
// RMS-quadratic twin, through a counting Evaluator, so the numbers measure twincal's own overhead
// around the Q-evaluations and count those evaluations.
#include <cstdint>
#include <optional>
#include <vector>

#include <benchmark/benchmark.h>

#include "twincal/models/bouncing_drift.hpp"
#include "twincal/models/evaluator.hpp"
#include "twincal/models/rms_quadratic_twin.hpp"

namespace twincal::benchmarks {

using CountedTwin = Evaluator<RmsQuadraticTwin>;
constexpr std::size_t episode_length = 100;

inline RmsQuadraticTwin make_twin(Index d) {
  RmsQuadraticTwinOptions options;
  options.assemblies.dimension = d;
  return RmsQuadraticTwin::generate(options, RandomStream(11));
}

// Runs assemblies in episodes; `make` builds a fresh controller for each episode. `counted` is
// `twin` behind a counting Evaluator (the controller's); the plant is `twin` itself.
template <int N, typename T, typename Counted, typename Make>
void run_episodes(benchmark::State& state, const T& twin, const Counted& counted, Make make) {
  const Index d = twin.control_dimension();
  const std::vector<AssemblyId> assemblies = twin.assemblies();
  using Controller = decltype(make(std::uint64_t{0}));
  constexpr bool scores_candidates = requires(const Controller& c) {
    c.last_proposal().candidates_scored;
  };
  std::optional<Controller> controller;
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
    if constexpr (scores_candidates) {
      scored += static_cast<double>(controller->last_proposal().candidates_scored);
    }
  }
  const auto iterations = static_cast<double>(state.iterations());
  state.counters["d"] = static_cast<double>(d);
  state.counters["Q_evals_per_assembly"] = static_cast<double>(evaluations) / iterations;
  if constexpr (scores_candidates) state.counters["scored_per_assembly"] = scored / iterations;
}

/// Runs episodes on make_twin(d) behind a counting Evaluator, d = N or, for Dynamic,
/// state.range(0); `make(counted, episode)` builds each episode's controller on `counted`.
/// Returns d.
template <int N, typename Make>
Index run_rms_quadratic_episodes(benchmark::State& state, Make make) {
  const Index d = N == Dynamic ? static_cast<Index>(state.range(0)) : N;
  const RmsQuadraticTwin twin = make_twin(d);
  const CountedTwin counted(twin);
  run_episodes<N>(state, twin, counted,
                  [&](std::uint64_t episode) { return make(counted, episode); });
  return d;
}

}  // namespace twincal::benchmarks
