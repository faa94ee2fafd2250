// The evaluator's parallel speedup for an expensive black box, and the per-step overhead of the
// measurement model's batch path with a cheap analytic twin.
//
// The black box burns a fixed amount of CPU work per control (calibrated once to ~1 ms on one
// idle core), not a fixed wall time: a wall-clock spin would "finish" on time even when two
// threads share one core and would fake the speedup.
#include <time.h>

#include <algorithm>
#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include <benchmark/benchmark.h>

#include "twincal/core/random_stream.hpp"
#include "twincal/models/evaluator.hpp"
#include "twincal/models/parallel_execution.hpp"
#include "twincal/models/quality_feedback.hpp"
#include "twincal/models/rms_quadratic_twin.hpp"

namespace twincal {
namespace {

// A dependent chain of multiply-adds: `rounds` of it cannot be vectorized away or overlapped.
double burn(std::uint64_t rounds, double seed) {
  double x = seed;
  for (std::uint64_t i = 0; i < rounds; ++i) x = x * 0.999999 + 1e-6;
  return x;
}

// CPU time of the calling thread: unlike wall time, not inflated when other processes share
// the core, so the calibration holds on a loaded machine.
double thread_cpu_seconds() {
  timespec now{};
  ::clock_gettime(CLOCK_THREAD_CPUTIME_ID, &now);
  return static_cast<double>(now.tv_sec) + 1e-9 * static_cast<double>(now.tv_nsec);
}

// Rounds of burn() that take ~1 ms of CPU (the fastest of several single-thread runs).
std::uint64_t rounds_per_millisecond() {
  static const std::uint64_t rounds = [] {
    constexpr std::uint64_t probe = 2'000'000;
    double fastest = 1e9;
    for (int trial = 0; trial < 7; ++trial) {
      const double start = thread_cpu_seconds();
      benchmark::DoNotOptimize(burn(probe, 0.5));
      fastest = std::min(fastest, thread_cpu_seconds() - start);
    }
    return static_cast<std::uint64_t>(static_cast<double>(probe) * 1e-3 / fastest);
  }();
  return rounds;
}

// The black box: ~1 ms per control, either of CPU work in this process (`waits` = false: an
// in-process model) or of waiting (`waits` = true: a twin whose work happens elsewhere, e.g. an
// FEM program on another machine, where threads overlap the waits whatever the local load).
struct MillisecondTwin {
  using Assembly = int;
  bool waits = false;
  std::vector<std::string> names{"A", "B", "C"};
  VectorX bounds = VectorX::Ones(3);
  std::uint64_t rounds = rounds_per_millisecond();

  [[nodiscard]] Index control_dimension() const { return 3; }
  [[nodiscard]] const std::vector<std::string>& locator_names() const { return names; }
  [[nodiscard]] const VectorX& lower_bounds() const { return bounds; }
  [[nodiscard]] const VectorX& upper_bounds() const { return bounds; }
  [[nodiscard]] double quality(int, const Eigen::Ref<const VectorX>& u) const {
    if (waits) {
      std::this_thread::sleep_for(std::chrono::milliseconds{1});
      return u.squaredNorm();
    }
    return burn(rounds, 1.0 + u.squaredNorm());
  }
  void quality_batch(int assembly, const Eigen::Ref<const MatrixX>& controls,
                     Eigen::Ref<VectorX> out) const {
    for (Index j = 0; j < controls.cols(); ++j) out(j) = quality(assembly, controls.col(j));
  }
};

MatrixX controls_for(Index k) {
  MatrixX controls(3, k);
  RandomStream(1).fill_normal(controls);
  return controls;
}

// Times `evaluator`'s batches of state.range(0) controls.
template <typename E>
void time_batches(benchmark::State& state, const E& evaluator) {
  const MatrixX controls = controls_for(state.range(0));
  VectorX out(controls.cols());
  for (auto _ : state) {
    evaluator.quality_batch(0, controls, out);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * controls.cols());
}

// Batch of k = 32 controls (2^(2+d) candidates for d = 3, the paper's look-ahead batch).
// Arguments: batch size, waits (0 = CPU work, 1 = waiting)[, threads].
void BM_SerialEvaluator(benchmark::State& state) {
  MillisecondTwin twin;
  twin.waits = state.range(1) != 0;
  const Evaluator<MillisecondTwin> evaluator(twin);
  time_batches(state, evaluator);
  state.counters["rounds_per_ms"] = static_cast<double>(twin.rounds);
}
BENCHMARK(BM_SerialEvaluator)
    ->Args({32, 0})
    ->Args({32, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_ParallelEvaluator(benchmark::State& state) {
  MillisecondTwin twin;
  twin.waits = state.range(1) != 0;
  const Evaluator<MillisecondTwin, ParallelExecution> evaluator(twin,
                                                                ParallelExecution(state.range(2)));
  time_batches(state, evaluator);
}
BENCHMARK(BM_ParallelEvaluator)
    ->Args({32, 0, 1})
    ->Args({32, 0, 2})
    ->Args({32, 1, 2})
    ->Args({32, 1, 4})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// The filter's per-step measurement: 2N+1 sigma points through QualityFeedback::measure_batch.
template <int N>
void BM_MeasureBatch(benchmark::State& state) {
  const Index d = state.range(0);
  RmsQuadraticTwinOptions options;
  options.assemblies.dimension = d;
  const RmsQuadraticTwin twin = RmsQuadraticTwin::generate(options, RandomStream(2));
  const QualityFeedback<RmsQuadraticTwin, N> model(twin, 1e-4);
  MatrixX states(d, 2 * d + 1);
  RandomStream(3).fill_normal(states);
  const typename QualityFeedback<RmsQuadraticTwin, N>::Inputs inputs{AssemblyId{1, 2},
                                                                     Vector<N>::Constant(d, 0.1)};
  VectorX out(states.cols());
  for (auto _ : state) {
    model.measure_batch(states, inputs, out);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * states.cols());
}
BENCHMARK(BM_MeasureBatch<3>)->Arg(3);
BENCHMARK(BM_MeasureBatch<Dynamic>)->Arg(3)->Arg(12);

}  // namespace
}  // namespace twincal
