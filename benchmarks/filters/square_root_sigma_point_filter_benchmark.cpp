// SquareRootSigmaPointFilter with Merwe's scaled points (the square-root UKF, 2n + 1 points), in
// both update forms (Joseph square root, the default, and the classic downdate), over
// {fixed, Dynamic} × n, for predict+update and for a preview into a kept one. The same problem as
// sigma_point_filter_benchmark.cpp (benchmark_problem.hpp), in a translation unit of its own so
// that the two compile in parallel.
#include <initializer_list>
#include <string>

#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include "benchmark_problem.hpp"
#include "twincal/filters/merwe_scaled_sigma_points.hpp"
#include "twincal/filters/quadratic_quality_measurement.hpp"
#include "twincal/filters/square_root_sigma_point_filter.hpp"

namespace twincal::benchmarks {
namespace {

template <int N>
auto make_filter(Index n, SquareRootUpdate update) {
  using Filter =
      SquareRootSigmaPointFilter<Walk<N>, QuadraticQualityMeasurement<N>, MerweScaledSigmaPoints>;
  return Filter(Walk<N>(n), measurement<N>(n), MerweScaledSigmaPoints{0.1, 2.0, 0.0},
                Vector<N>::Zero(n), SquareMatrix<N>(SquareMatrix<N>::Identity(n, n) * 1e-3),
                SquareRootFilterOptions{SigmaPointRefresh::redraw, update});
}

template <int N>
void predict_update(benchmark::State& state, SquareRootUpdate update) {
  const Index n = N == Dynamic ? static_cast<Index>(state.range(0)) : N;
  auto filter = make_filter<N>(n, update);
  const auto in = inputs<N>(n);
  for (auto _ : state) {
    filter.predict();
    filter.update(0.2, in);
    benchmark::DoNotOptimize(filter.state().data());
  }
}

template <int N>
void preview(benchmark::State& state, SquareRootUpdate update) {
  const Index n = N == Dynamic ? static_cast<Index>(state.range(0)) : N;
  auto filter = make_filter<N>(n, update);
  const auto in = inputs<N>(n);
  filter.predict();
  auto p = filter.preview(in);
  for (auto _ : state) {
    filter.preview(in, p);
    benchmark::DoNotOptimize(p.posterior_factor.data());
  }
}

template <int... Ns>
void register_form(const char* form, SquareRootUpdate update,
                   std::initializer_list<int> dynamic_sizes) {
  (benchmark::RegisterBenchmark(fmt::format("sr_ukf_{}/fixed/predict_update/{}", form, Ns).c_str(),
                                [update](benchmark::State& s) { predict_update<Ns>(s, update); }),
   ...);
  (benchmark::RegisterBenchmark(fmt::format("sr_ukf_{}/fixed/preview/{}", form, Ns).c_str(),
                                [update](benchmark::State& s) { preview<Ns>(s, update); }),
   ...);
  for (const int n : dynamic_sizes) {
    benchmark::RegisterBenchmark(
        fmt::format("sr_ukf_{}/dynamic/predict_update", form).c_str(),
        [update](benchmark::State& s) { predict_update<Dynamic>(s, update); })
        ->Arg(n);
    benchmark::RegisterBenchmark(fmt::format("sr_ukf_{}/dynamic/preview", form).c_str(),
                                 [update](benchmark::State& s) { preview<Dynamic>(s, update); })
        ->Arg(n);
  }
}

const bool registered = [] {
  register_form<1, 3, 6, 12>("joseph", SquareRootUpdate::joseph, {1, 3, 6, 12, 32});
  register_form<1, 3, 6, 12>("downdate", SquareRootUpdate::downdate, {1, 3, 6, 12, 32});
  return true;
}();

}  // namespace
}  // namespace twincal::benchmarks
