// Time of one budgeted search of u0 (eq. 3) on the analytic key-point twin with contact, over
// d = 3 and 12 at B = 2 (d + 1)² evaluations from the affine optimum (the additive start's
// analog): the search's own cost beside the twin's, which a real twin multiplies by its seconds
// per call. LeastSquaresSearch works on the key points' deviations, TrustRegionSearch on Q²;
// counters give the evaluations and requests per search (docs/benchmarks.md, "Budgeted u0").
#include <cstdint>
#include <utility>
#include <vector>

#include <benchmark/benchmark.h>

#include "twincal/controllers/least_squares_search.hpp"
#include "twincal/controllers/trust_region_search.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/models/contact_nonlinearity.hpp"
#include "twincal/models/key_point_twin.hpp"

namespace {

using namespace twincal;

struct ContactCase {
  KeyPointTwin<ContactNonlinearity> twin;
  std::vector<AssemblyId> assemblies;
  std::uint64_t budget;

  explicit ContactCase(Index d)
      : twin(options(d), RandomStream(11)),
        assemblies(twin.assemblies()),
        budget(static_cast<std::uint64_t>(2 * (d + 1) * (d + 1))) {}
  static KeyPointTwinOptions options(Index d) {
    KeyPointTwinOptions o;
    o.assemblies.dimension = d;
    return o;
  }
};

// Runs `search(assembly)` for the assemblies in turn, one per iteration; the search returns its
// evaluations and batches.
template <typename Search>
void run_searches(benchmark::State& state, const ContactCase& c, Search search) {
  std::size_t next = 0;
  double evaluations = 0.0;
  double batches = 0.0;
  for (auto _ : state) {
    const AssemblyId& assembly = c.assemblies[next];
    next = (next + 1) % c.assemblies.size();
    const auto [spent, requests] = search(assembly);
    evaluations += static_cast<double>(spent);
    batches += static_cast<double>(requests);
  }
  const auto n = static_cast<double>(state.iterations());
  state.counters["evaluations"] = evaluations / n;
  state.counters["requests"] = batches / n;
}

void BM_LeastSquaresSearchOnContact(benchmark::State& state) {
  const ContactCase c(state.range(0));
  const LeastSquaresSearch search({.evaluations = c.budget});
  const RandomStream restarts(12);
  run_searches(state, c, [&](const AssemblyId& assembly) {
    const DeviationObjective objective = [&](const Eigen::Ref<const MatrixX>& controls,
                                             Eigen::Ref<MatrixX> deviations) {
      c.twin.deviations_batch(assembly, controls, deviations);
    };
    const LeastSquaresSearchResult result = search.minimize(
        objective, c.twin.key_point_count(), c.twin.search_start(assembly), c.twin.lower_bounds(),
        c.twin.upper_bounds(),
        restarts.substream(static_cast<std::uint64_t>(assembly.upper * 100 + assembly.lower)));
    benchmark::DoNotOptimize(result.minimum);
    return std::pair{result.evaluations, result.batches};
  });
}

void BM_TrustRegionSearchOnContact(benchmark::State& state) {
  const ContactCase c(state.range(0));
  const TrustRegionSearch search({.evaluations = c.budget});
  run_searches(state, c, [&](const AssemblyId& assembly) {
    const BatchObjective objective = [&](const Eigen::Ref<const MatrixX>& controls,
                                         Eigen::Ref<VectorX> qualities) {
      c.twin.quality_batch(assembly, controls, qualities);
    };
    const TrustRegionSearchResult result = search.minimize(
        objective, c.twin.search_start(assembly), c.twin.lower_bounds(), c.twin.upper_bounds());
    benchmark::DoNotOptimize(result.minimum);
    return std::pair{result.evaluations, result.batches};
  });
}

}  // namespace

BENCHMARK(BM_LeastSquaresSearchOnContact)->Arg(3)->Arg(12)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_TrustRegionSearchOnContact)->Arg(3)->Arg(12)->Unit(benchmark::kMicrosecond);
