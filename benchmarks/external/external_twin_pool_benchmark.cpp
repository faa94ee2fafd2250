// ExternalTwinPool's speed-up for a twin that waits: tests/data/script_twin.py sleeping 50 ms
// per control, one batch of 231 controls (the paper's w-controller at d = 3: 33 candidates × 7
// sigma points) spread over N = 1 … 16 worker processes. The workers sleep rather than compute,
// so the speed-up is not bounded by the machine's cores; the ideal is 231 × 50 ms / ⌈231/N⌉.
#include <chrono>

#include <benchmark/benchmark.h>

#include "twincal/external/external_twin_pool.hpp"

namespace twincal {
namespace {

constexpr Index kBatch = 231;
constexpr double kSecondsPerControl = 0.05;

void BM_ExternalTwinPool_SleepingBatch(benchmark::State& state) {
  ExternalTwinPoolOptions options;
  options.twin.command = {TWINCAL_TEST_DATA_DIR "/script_twin.py"};
  options.twin.locator_names = {"A", "B", "C"};
  options.twin.timeout = std::chrono::milliseconds{60'000};
  options.workers = state.range(0);
  const ExternalTwinPool pool(options);
  const nlohmann::json assembly = {
      {"q0", 0.25}, {"a", {0.1, -0.2, 0.0}}, {"sleep", kSecondsPerControl}};
  const MatrixX controls = MatrixX::Random(3, kBatch) * 0.1;
  VectorX out(kBatch);
  pool.quality_batch(assembly, controls.leftCols(pool.workers()), out.head(pool.workers()));
  for (auto _ : state) {
    pool.quality_batch(assembly, controls, out);
    benchmark::DoNotOptimize(out.data());
  }
  const double serial = static_cast<double>(kBatch) * kSecondsPerControl;
  state.counters["speedup"] = benchmark::Counter(serial * static_cast<double>(state.iterations()),
                                                 benchmark::Counter::kIsRate);
  state.counters["workers"] = static_cast<double>(pool.workers());
}
BENCHMARK(BM_ExternalTwinPool_SleepingBatch)
    ->Arg(1)
    ->Arg(2)
    ->Arg(4)
    ->Arg(8)
    ->Arg(16)
    ->Iterations(2)
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace twincal
