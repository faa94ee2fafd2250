// One episode of the paper's protocol (100 assemblies, eq. 15 drift) per twin case, locator set
// and controller: what `twincal paper` spends per episode (1040 of them for the whole matrix).
#include <string>

#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include "twincal/experiments/episode_runner.hpp"
#include "twincal/experiments/twin_cases.hpp"

namespace twincal {
namespace {

void episode(benchmark::State& state, ExperimentConfig config, const ControllerSpec& spec) {
  const CaseTwin twin = make_case_twin(config);
  for (auto _ : state) {
    EpisodeResult result = run_episode(twin, config, spec, 0);
    benchmark::DoNotOptimize(result.relative_residual);
  }
  state.counters["assemblies/s"] = benchmark::Counter(
      static_cast<double>(state.iterations() * config.assemblies), benchmark::Counter::kIsRate);
}

const bool registered = [] {
  for (const TwinCase twin_case : {TwinCase::analytic, TwinCase::body, TwinCase::door}) {
    for (const char* locators : {"A", "ABC"}) {
      for (const ControllerSpec& spec :
           {ControllerSpec::baseline(), ControllerSpec::default_controller(),
            ControllerSpec::lookahead(0.5), ControllerSpec::lookahead(1.0)}) {
        ExperimentConfig config;
        config.twin_case = twin_case;
        config.locators = locators;
        const std::string name =
            fmt::format("Episode/{}/{}/{}", to_string(twin_case), locators, spec.label());
        benchmark::RegisterBenchmark(name.c_str(), episode, config, spec)
            ->Unit(benchmark::kMicrosecond);
      }
    }
  }
  return true;
}();

}  // namespace
}  // namespace twincal
