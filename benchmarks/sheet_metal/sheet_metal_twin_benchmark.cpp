// The open FEM twin: the per-case precomputation (mesh, two factorizations, the affine influence
// maps and the per-assembly optima) and one quality evaluation Q(x, u).
#include <benchmark/benchmark.h>

#include "twincal/core/random_stream.hpp"
#include "twincal/sheet_metal/sheet_metal_twin.hpp"

namespace twincal {
namespace {

void BM_SheetMetalTwinPrecompute(benchmark::State& state) {
  const auto which = static_cast<SheetMetalCase>(state.range(0));
  for (auto _ : state) {
    SheetMetalTwin twin = SheetMetalTwin::make(which, 2023);
    benchmark::DoNotOptimize(twin);
  }
  state.SetLabel(which == SheetMetalCase::body ? "body" : "door");
}
BENCHMARK(BM_SheetMetalTwinPrecompute)
    ->Arg(static_cast<int>(SheetMetalCase::body))
    ->Arg(static_cast<int>(SheetMetalCase::door))
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3);

void BM_SheetMetalTwinQuality(benchmark::State& state) {
  const auto which = static_cast<SheetMetalCase>(state.range(0));
  const SheetMetalTwin twin = SheetMetalTwin::make(which, 2023);
  RandomStream stream(1);
  VectorX control(twin.control_dimension());
  stream.fill_normal(control);
  const AssemblyId assembly{4, 6};
  for (auto _ : state) {
    benchmark::DoNotOptimize(control.data());
    benchmark::DoNotOptimize(twin.quality(assembly, control));
  }
  state.SetLabel(which == SheetMetalCase::body ? "body, d = 12" : "door, d = 19");
}
BENCHMARK(BM_SheetMetalTwinQuality)
    ->Arg(static_cast<int>(SheetMetalCase::body))
    ->Arg(static_cast<int>(SheetMetalCase::door))
    ->Unit(benchmark::kNanosecond);

}  // namespace
}  // namespace twincal
