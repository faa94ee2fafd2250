// twincal_budgeted_optimum: how close a budgeted u0 search (from controllers' AdditiveWarmStart,
// as `optimum_budget` runs it for the external case) comes to the full or exact optimum of a
// case's 100 assemblies (docs/benchmarks.md, "Budgeted u0").
//   twincal_budgeted_optimum CASE [D] [FACTOR] [SEED] [METHOD] [--list]
// CASE: analytic | contact | stiffening | kink (the analytic family, D locators) | body | door |
// body-contact | door-contact, or a config file (NAME.json, as `twincal run --config` reads it;
// D is then unused) whose twin is searched: the external case's program, its reference
// z* the config's own u0 search; budget B = FACTOR (d + 1)² (FACTOR 1 by default); the first row
// and column get 2B from the centre, the others B from the additive start. The reference z* is the
// case's own: exact (analytic RMS-quadratic, body, door) or the full search (DIRECT-L then
// BOBYQA, 2000 + 1000 evaluations; the FEM contact cases: BOBYQA from the linear optimum).
// METHOD: bobyqa (NLopt's BOBYQA alone, one evaluation per request; the default), trust_region
// (controllers' TrustRegionSearch on Q², a batch per request) or least_squares (controllers'
// LeastSquaresSearch on the key points' deviations, for the cases whose twin answers them: all
// but the RMS-quadratic analytic, and an external program with key_points; its restarts draw from
// RandomStream(SEED).substream("least_squares")), or least_squares_speculative (the same, each
// start and step asked for with its Jacobian's stencil in one request). --list prints every
// assembly's result too.
// Prints the mean evaluations and requests (rounds of the twin's latency) per assembly, and for
// trust_region and least_squares how the assemblies beyond 1 % ended (converged or out of
// budget).

#include <algorithm>
#include <cstdio>
#include <string>
#include <string_view>
#include <vector>

#include "twincal/controllers/additive_warm_start.hpp"
#include "twincal/controllers/individual_optimum.hpp"
#include "twincal/controllers/least_squares_search.hpp"
#include "twincal/controllers/trust_region_search.hpp"
#include "twincal/experiments/config_file.hpp"
#include "twincal/experiments/experiment_choices.hpp"
#include "twincal/experiments/external_twin_settings.hpp"
#include "twincal/experiments/twin_cases.hpp"

namespace {

using namespace twincal;

// One budgeted search of every assembly of `twin` with `method`, in AdditiveWarmStart's phases,
// each compared with the twin's reference z*; prints the summary line (and with `list` each
// assembly first).
void search_every_assembly(const AnyTwin& twin, const std::string& which, const std::string& method,
                           double factor, std::uint64_t seed, bool list) {
  const Index d = twin.control_dimension();
  const auto budget = static_cast<std::uint64_t>(factor * static_cast<double>((d + 1) * (d + 1)));
  std::vector<AssemblyId> order = twin.assemblies();
  std::stable_sort(order.begin(), order.end(), [](const AssemblyId& a, const AssemblyId& b) {
    return AdditiveWarmStart::phase(a) < AdditiveWarmStart::phase(b);
  });
  AdditiveWarmStart warm(twin.lower_bounds(), twin.upper_bounds());
  const VectorX centre = 0.5 * (twin.lower_bounds() + twin.upper_bounds());
  const RandomStream restarts = RandomStream(seed).substream("least_squares");
  std::vector<double> gaps;
  std::uint64_t evaluations = 0;
  std::uint64_t requests = 0;
  // Of the assemblies beyond 1 %, those whose search converged (the trust region's radius
  // collapsed at a local minimum or a kink it could not cross; least squares' last local search
  // converged and too little budget was left for another) rather than spending its budget.
  long converged_misses = 0;
  for (const AssemblyId& assembly : order) {
    const std::uint64_t allowed = AdditiveWarmStart::phase(assembly) == 0 ? 2 * budget : budget;
    const VectorX start = warm.start(assembly, centre);
    const double reference = twin.optimal_quality(assembly);
    IndividualControl found;
    bool converged = false;  // trust_region and least_squares
    if (method == "bobyqa") {
      NloptOptimizerOptions options;
      options.global_evaluations = 0;
      options.local_evaluations = allowed;
      found = IndividualOptimum<AnyTwin>(twin, NloptOptimizer(options)).optimize(assembly, start);
      requests += found.evaluations;
    } else if (least_squares_method(method)) {
      const LeastSquaresSearch search(least_squares_options(method, allowed));
      const DeviationObjective objective = [&](const Eigen::Ref<const MatrixX>& controls,
                                               Eigen::Ref<MatrixX> deviations) {
        twin.deviations_batch(assembly, controls, deviations);
      };
      const LeastSquaresSearchResult result = search.minimize(
          objective, twin.key_point_count(), start, twin.lower_bounds(), twin.upper_bounds(),
          restarts.substream(fmt::format("{} {}", assembly.upper, assembly.lower)));
      found = {result.argmin, result.minimum, result.evaluations};
      requests += static_cast<std::uint64_t>(result.batches);
      converged = result.status == LeastSquaresStatus::converged;
    } else {
      const TrustRegionSearch search({.evaluations = allowed});
      const BatchObjective objective = [&](const Eigen::Ref<const MatrixX>& controls,
                                           Eigen::Ref<VectorX> qualities) {
        twin.quality_batch(assembly, controls, qualities);
      };
      const TrustRegionSearchResult result =
          search.minimize(objective, start, twin.lower_bounds(), twin.upper_bounds());
      found = {result.argmin, result.minimum, result.evaluations};
      requests += static_cast<std::uint64_t>(result.batches);
      converged = result.status == TrustRegionStatus::converged;
    }
    warm.record(assembly, found.control);
    evaluations += found.evaluations;
    const double gap = (found.quality - reference) / reference;
    if (gap > 0.01 && converged) ++converged_misses;
    gaps.push_back(gap);
    if (list) {
      std::printf("assembly %ld %ld: %.12g (reference %.12g, gap %.3e), %llu evaluations\n",
                  static_cast<long>(assembly.upper), static_cast<long>(assembly.lower),
                  found.quality, reference, gap,
                  static_cast<unsigned long long>(found.evaluations));
    }
  }
  std::sort(gaps.begin(), gaps.end());
  const std::size_t n = gaps.size();
  const auto within = std::count_if(gaps.begin(), gaps.end(), [](double g) { return g <= 0.01; });
  // Assemblies where the budgeted search beat the reference by more than 1 %: where that is the
  // full search, it missed a better basin.
  const auto beyond = std::count_if(gaps.begin(), gaps.end(), [](double g) { return g < -0.01; });
  std::printf(
      "%s %s d=%ld seed=%llu budget=%llu: mean evaluations per assembly %.1f in %.1f requests "
      "(4(d+1)^2 = %ld); "
      "relative gap to z*: median %.2e, 90th percentile %.2e, max %.2e, min %.2e; within 1 %%: "
      "%ld/%zu; more than 1 %% below z*: %ld",
      which.c_str(), method.c_str(), static_cast<long>(d), static_cast<unsigned long long>(seed),
      static_cast<unsigned long long>(budget), static_cast<double>(evaluations) / double(n),
      static_cast<double>(requests) / double(n), static_cast<long>(4 * (d + 1) * (d + 1)),
      gaps[n / 2], gaps[n * 9 / 10], gaps.back(), gaps.front(), static_cast<long>(within), n,
      static_cast<long>(beyond));
  if (method != "bobyqa") {
    std::printf(" (of the %ld beyond 1 %%, %ld converged, %ld spent the budget)",
                static_cast<long>(n) - static_cast<long>(within), converged_misses,
                static_cast<long>(n) - static_cast<long>(within) - converged_misses);
  }
  std::printf("\n");
}

}  // namespace

int main(int argc, char** argv) {
  using namespace twincal;
  if (argc < 2) {
    std::fprintf(stderr,
                 "usage: twincal_budgeted_optimum CASE|CONFIG.json [D] [FACTOR] [SEED] "
                 "[bobyqa|trust_region|least_squares|least_squares_speculative] [--list]\n");
    return 2;
  }
  try {
    const std::string which = argv[1];
    ExperimentConfig config;
    if (which.ends_with(".json")) {
      config = read_config_file(which).get<ExperimentConfig>();  // the config names its twin
    } else if (which == "analytic" || which == "contact" || which == "stiffening" ||
               which == "kink") {
      config.twin_case = TwinCase::analytic;
      config.analytic_dimension = argc > 2 ? std::stol(argv[2]) : 3;
      if (which != "analytic") config.nonlinearity = parse_enum<Nonlinearity>(which, "CASE");
    } else {
      config.twin_case = parse_enum<TwinCase>(which, "CASE");
    }
    config.twin_seed = argc > 4 ? std::stoull(argv[4]) : 2023;
    const double factor = argc > 3 ? std::stod(argv[3]) : 1.0;
    // One method or several, comma-separated: each runs on the same twin, whose reference is
    // computed once (a config's external twin may take hours for it).
    std::vector<std::string> methods;
    for (std::string_view rest = argc > 5 ? argv[5] : "bobyqa"; !rest.empty();) {
      const std::size_t comma = std::min(rest.find(','), rest.size());
      methods.emplace_back(rest.substr(0, comma));
      rest.remove_prefix(std::min(comma + 1, rest.size()));
    }
    const bool list = argc > 6 && std::string(argv[6]) == "--list";
    for (const std::string& method : methods) {
      if (method != "bobyqa" && method != "trust_region" && !least_squares_method(method)) {
        throw InvalidArgumentError("METHOD", "METHOD: value is '" + method +
                                                 "'; rule: must be bobyqa, trust_region, "
                                                 "least_squares or least_squares_speculative (or "
                                                 "a comma-separated list)");
      }
    }
    const AnyTwin twin = make_twin(config);
    if (std::ranges::count_if(methods, least_squares_method) > 0 && twin.key_point_count() == 0) {
      throw InvalidArgumentError("CASE", "CASE: value is '" + which +
                                             "'; rule: least_squares needs a twin that answers "
                                             "its key points' deviations");
    }
    for (const std::string& method : methods) {
      search_every_assembly(twin, which, method, factor, config.twin_seed, list);
    }
  } catch (const std::exception& error) {
    std::fprintf(stderr, "twincal_budgeted_optimum: %s\n", error.what());
    return 1;
  }
  return 0;
}
