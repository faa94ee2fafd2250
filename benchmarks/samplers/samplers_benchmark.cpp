// Points per second of the samplers and the Gaussian transform at d ∈ {3, 32, 1000}, batches of
// 1024 points (a power of two, so Sobol's balance check stays quiet). Boost.Random's
// boost::random::sobol is the reference for our Sobol: it returns one 64-bit integer per call,
// scaled here by 2^-64 into the same d × n column-major batch.
#include <cmath>
#include <cstdint>

#include <benchmark/benchmark.h>
#include <boost/random/sobol.hpp>

#include "twincal/samplers/candidates.hpp"
#include "twincal/samplers/gaussian_transform.hpp"
#include "twincal/samplers/halton.hpp"
#include "twincal/samplers/latin_hypercube.hpp"
#include "twincal/samplers/pseudo_random.hpp"
#include "twincal/samplers/sobol.hpp"

namespace {

using twincal::Index;
using twincal::MatrixX;

constexpr Index batch = 1024;

void dimensions(benchmark::internal::Benchmark* b) {
  for (const int d : {3, 32, 1000}) b->Arg(d);
}

template <typename S>
void run_sampler(benchmark::State& state, S& sampler) {
  MatrixX points(sampler.dimension(), batch);
  for (auto _ : state) {
    sampler.fill(points);
    benchmark::DoNotOptimize(points.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * batch);
}

template <twincal::SobolRandomization R>
void BM_Sobol(benchmark::State& state) {
  // Default resolution (bits = 32, 2^32 points: more than any run here draws).
  twincal::Sobol sobol(state.range(0), {.randomization = R, .seed = 1});
  run_sampler(state, sobol);
}
BENCHMARK_TEMPLATE(BM_Sobol, twincal::SobolRandomization::none)->Apply(dimensions);
BENCHMARK_TEMPLATE(BM_Sobol, twincal::SobolRandomization::linear_matrix_scramble)
    ->Apply(dimensions);
BENCHMARK_TEMPLATE(BM_Sobol, twincal::SobolRandomization::owen)->Apply(dimensions);

void BM_BoostSobol(benchmark::State& state) {
  boost::random::sobol sobol(static_cast<std::size_t>(state.range(0)));
  MatrixX points(state.range(0), batch);
  for (auto _ : state) {
    double* out = points.data();
    for (Index i = 0; i < points.size(); ++i)
      out[i] = std::ldexp(static_cast<double>(sobol()), -64);
    benchmark::DoNotOptimize(points.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * batch);
}
BENCHMARK(BM_BoostSobol)->Apply(dimensions);

void BM_Halton(benchmark::State& state) {
  twincal::Halton halton(state.range(0));
  run_sampler(state, halton);
}
BENCHMARK(BM_Halton)->Apply(dimensions);

void BM_HaltonScrambled(benchmark::State& state) {
  twincal::Halton halton(state.range(0), {.scramble = true, .seed = 1});
  run_sampler(state, halton);
}
BENCHMARK(BM_HaltonScrambled)->Apply(dimensions);

void BM_PseudoRandom(benchmark::State& state) {
  twincal::PseudoRandom random(state.range(0), {.seed = 1});
  run_sampler(state, random);
}
BENCHMARK(BM_PseudoRandom)->Apply(dimensions);

void BM_LatinHypercube(benchmark::State& state) {
  twincal::LatinHypercube lhs(state.range(0), {.seed = 1});
  run_sampler(state, lhs);
}
BENCHMARK(BM_LatinHypercube)->Apply(dimensions);

// The transform alone (uniform batch fixed): Φ⁻¹ per coordinate plus the factor product.
template <int N>
void run_transform(benchmark::State& state, twincal::GaussianFactorization factorization) {
  const Index d = state.range(0);
  MatrixX root = MatrixX::Random(d, d);
  const MatrixX covariance = root * root.transpose() + MatrixX::Identity(d, d);
  const twincal::GaussianTransform<N> transform(twincal::VectorX::Zero(d), covariance,
                                                {.factorization = factorization});
  twincal::Sobol sobol(d, {.randomization = twincal::SobolRandomization::linear_matrix_scramble});
  MatrixX uniform(d, batch);
  sobol.fill(uniform);
  twincal::Matrix<N, twincal::Dynamic> out(d, batch);
  for (auto _ : state) {
    transform.transform(uniform, out);
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * batch);
}

void BM_GaussianTransformCholesky(benchmark::State& state) {
  run_transform<twincal::Dynamic>(state, twincal::GaussianFactorization::cholesky);
}
BENCHMARK(BM_GaussianTransformCholesky)->Apply(dimensions);

void BM_GaussianTransformEigen(benchmark::State& state) {
  run_transform<twincal::Dynamic>(state, twincal::GaussianFactorization::eigen);
}
BENCHMARK(BM_GaussianTransformEigen)->Apply(dimensions);

void BM_GaussianTransformFixed3(benchmark::State& state) {
  run_transform<3>(state, twincal::GaussianFactorization::cholesky);
}
BENCHMARK(BM_GaussianTransformFixed3)->Arg(3);

// The paper's per-assembly proposal (Sec. 3): d = 3, 2^(2+d) = 32 scrambled Sobol points mapped
// to N(û*, 1e-3·I), those outside |u_i − û*_i| <= 0.1 dropped.
void BM_PaperCandidates(benchmark::State& state) {
  const twincal::Vector<3> mean(0.1, -0.2, 0.05);
  const twincal::GaussianTransform<3> transform(mean, 1e-3 * twincal::SquareMatrix<3>::Identity());
  const auto box = twincal::BoxSet<3>::cube(mean, 0.1);
  twincal::Sobol sobol(3, {.randomization = twincal::SobolRandomization::linear_matrix_scramble});
  twincal::CandidateSet<3> set;  // redrawn in place: no allocation per call
  for (auto _ : state) {
    set.draw(sobol, transform, box, {.count = 32});
    benchmark::DoNotOptimize(set.points().data());
  }
  state.SetItemsProcessed(state.iterations() * 32);
}
BENCHMARK(BM_PaperCandidates);

}  // namespace
