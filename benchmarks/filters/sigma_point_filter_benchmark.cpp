// SigmaPointFilter with Merwe's scaled points (the paper's UKF, 2n + 1 points), the
// spherical-radial cubature points (the CKF, 2n) and the fifth-degree rule (2n² + 1). Julier's and
// the simplex points cost what a set of the same point count costs, so they are not repeated.
// Each is run over {fixed, Dynamic} × n, for predict+update and for a preview (what a look-ahead
// controller pays per candidate control), with the cheap analytic QuadraticQualityMeasurement
// (H = I) and a random-walk state model. One translation unit for all three: they share the
// Eigen kernels of each size, which are most of the compile time (split in two, the pair took 224 s
// and the fifth-degree rule 137 s to compile, against 256 s together).
#include <initializer_list>
#include <string>

#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include "benchmark_problem.hpp"
#include "twincal/filters/fifth_degree_cubature_sigma_points.hpp"
#include "twincal/filters/merwe_scaled_sigma_points.hpp"
#include "twincal/filters/quadratic_quality_measurement.hpp"
#include "twincal/filters/sigma_point_filter.hpp"
#include "twincal/filters/spherical_radial_sigma_points.hpp"

namespace twincal::benchmarks {
namespace {

template <typename Case, int N>
auto make_filter(Index n) {
  using Scheme = decltype(Case::make());
  using Filter = SigmaPointFilter<Walk<N>, QuadraticQualityMeasurement<N>, Scheme>;
  return Filter(Walk<N>(n), measurement<N>(n), Case::make(), Vector<N>::Zero(n),
                SquareMatrix<N>::Identity(n, n) * 1e-3);
}

template <typename Case, int N>
void predict_update(benchmark::State& state) {
  const Index n = N == Dynamic ? static_cast<Index>(state.range(0)) : N;
  auto filter = make_filter<Case, N>(n);
  const auto in = inputs<N>(n);
  for (auto _ : state) {
    filter.predict();
    filter.update(0.2, in);
    benchmark::DoNotOptimize(filter.state().data());
  }
  state.counters["points"] = static_cast<double>(filter.num_points());
}

template <typename Case, int N>
void preview(benchmark::State& state) {
  const Index n = N == Dynamic ? static_cast<Index>(state.range(0)) : N;
  auto filter = make_filter<Case, N>(n);
  const auto in = inputs<N>(n);
  filter.predict();
  // Into one kept preview, as a controller's loop over candidate controls does: the cost of the
  // update's algebra, not of allocating a fresh Preview at Dynamic sizes.
  auto p = filter.preview(in);
  for (auto _ : state) {
    filter.preview(in, p);
    benchmark::DoNotOptimize(p.posterior_covariance.data());
  }
  state.counters["points"] = static_cast<double>(filter.num_points());
}

template <typename Case, int... Ns>
void register_case(std::initializer_list<int> dynamic_sizes) {
  (benchmark::RegisterBenchmark(fmt::format("{}/fixed/predict_update/{}", Case::name, Ns).c_str(),
                                &predict_update<Case, Ns>),
   ...);
  (benchmark::RegisterBenchmark(fmt::format("{}/fixed/preview/{}", Case::name, Ns).c_str(),
                                &preview<Case, Ns>),
   ...);
  for (const int n : dynamic_sizes) {
    benchmark::RegisterBenchmark(fmt::format("{}/dynamic/predict_update", Case::name).c_str(),
                                 &predict_update<Case, Dynamic>)
        ->Arg(n);
    benchmark::RegisterBenchmark(fmt::format("{}/dynamic/preview", Case::name).c_str(),
                                 &preview<Case, Dynamic>)
        ->Arg(n);
  }
}

struct Ukf {
  static constexpr const char* name = "ukf_merwe";
  static MerweScaledSigmaPoints make() { return {0.1, 2.0, 0.0}; }
};

struct Ckf {
  static constexpr const char* name = "ckf";
  static SphericalRadialSigmaPoints make() { return {}; }
};

struct FifthDegree {
  static constexpr const char* name = "fifth_degree";
  static FifthDegreeCubatureSigmaPoints make() { return {}; }
};

// Fixed sizes 19 and 32 (39 × 19 and 65 × 32 point matrices) take minutes to compile and run no
// faster than Dynamic (docs/benchmarks.md), so they are built only on request:
// -DTWINCAL_BENCHMARK_LARGE_FIXED_SIZES=ON.
const bool registered = [] {
#ifdef TWINCAL_BENCHMARK_LARGE_FIXED_SIZES
  register_case<Ukf, 1, 2, 3, 6, 12, 19, 32>({1, 2, 3, 6, 12, 19, 32});
  register_case<Ckf, 1, 2, 3, 6, 12, 19, 32>({1, 2, 3, 6, 12, 19, 32});
#else
  register_case<Ukf, 1, 2, 3, 6, 12>({1, 2, 3, 6, 12, 19, 32});
  register_case<Ckf, 1, 2, 3, 6, 12>({1, 2, 3, 6, 12, 19, 32});
#endif
  // 289 points at n = 12 and 2049 at n = 32: fixed n <= 6, dynamic n <= 12.
  register_case<FifthDegree, 1, 2, 3, 6>({1, 2, 3, 6, 12});
  return true;
}();

}  // namespace
}  // namespace twincal::benchmarks
