// Cholesky factorization and rank-one update, fixed vs dynamic size, over the dimensions the
// paper's cases use (1–3 drifting locators, 12 body and 19 door locators) and beyond.
#include <benchmark/benchmark.h>

#include "twincal/core/cholesky.hpp"
#include "twincal/core/random_stream.hpp"

namespace {

template <int N>
twincal::SquareMatrix<N> random_spd(twincal::Index n) {
  twincal::RandomStream stream(17);
  twincal::SquareMatrix<N> a(n, n);
  stream.fill_normal(a);
  twincal::SquareMatrix<N> p = a * a.transpose();
  p.diagonal().array() += static_cast<double>(n);
  return p;
}

template <int N>
void BM_Cholesky(benchmark::State& state) {
  const auto n = N == twincal::Dynamic ? static_cast<twincal::Index>(state.range(0)) : N;
  const twincal::SquareMatrix<N> p = random_spd<N>(n);
  for (auto _ : state) {
    twincal::CholeskyResult<N> result = twincal::cholesky(p);
    benchmark::DoNotOptimize(result.factor.lower().data());
  }
  state.counters["n"] = static_cast<double>(n);
}

template <int N>
void BM_RankOneUpdate(benchmark::State& state) {
  const auto n = N == twincal::Dynamic ? static_cast<twincal::Index>(state.range(0)) : N;
  twincal::CholeskyFactor<N> factor = twincal::cholesky(random_spd<N>(n)).factor;
  const twincal::Vector<N> v = twincal::Vector<N>::Constant(n, 1e-3);
  double sigma = 1.0;
  for (auto _ : state) {
    factor.rank_one_update(v, sigma);
    sigma = -sigma;  // alternate update and downdate so the factor stays bounded
    benchmark::DoNotOptimize(factor.lower().data());
  }
  state.counters["n"] = static_cast<double>(n);
}

}  // namespace

BENCHMARK(BM_Cholesky<1>);
BENCHMARK(BM_Cholesky<3>);
BENCHMARK(BM_Cholesky<12>);
BENCHMARK(BM_Cholesky<twincal::Dynamic>)->Arg(1)->Arg(3)->Arg(12)->Arg(19)->Arg(32);
BENCHMARK(BM_RankOneUpdate<3>);
BENCHMARK(BM_RankOneUpdate<12>);
BENCHMARK(BM_RankOneUpdate<twincal::Dynamic>)->Arg(3)->Arg(12)->Arg(19)->Arg(32);
