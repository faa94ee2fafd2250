// Compile-time checks of the Sampler concepts: what they accept (every twincal sampler) and
// what they reject. A failing static_assert fails the build, naming the requirement.
#include <cstdint>

#include "twincal/samplers/halton.hpp"
#include "twincal/samplers/latin_hypercube.hpp"
#include "twincal/samplers/pseudo_random.hpp"
#include "twincal/samplers/sampler.hpp"
#include "twincal/samplers/sobol.hpp"

namespace twincal::static_checks {

struct CompleteSampler {
  [[nodiscard]] Index dimension() const { return 2; }
  void seed(std::uint64_t) {}
  void discard(std::uint64_t) {}
  void fill(Eigen::Ref<MatrixX>) {}
};
struct SamplerWithoutDiscard {
  [[nodiscard]] Index dimension() const { return 2; }
  void seed(std::uint64_t) {}
  void fill(Eigen::Ref<MatrixX>) {}
};
struct SamplerWithoutFill {
  [[nodiscard]] Index dimension() const { return 2; }
  void seed(std::uint64_t) {}
  void discard(std::uint64_t) {}
};
struct SamplerWithoutSeed {
  [[nodiscard]] Index dimension() const { return 2; }
  void discard(std::uint64_t) {}
  void fill(Eigen::Ref<MatrixX>) {}
};
struct SamplerWithMutableDimension {  // dimension() must be callable on a const sampler
  Index dimension() { return 2; }
  void seed(std::uint64_t) {}
  void discard(std::uint64_t) {}
  void fill(Eigen::Ref<MatrixX>) {}
};
static_assert(Sampler<CompleteSampler>);
static_assert(!Sampler<SamplerWithoutDiscard>);
static_assert(!Sampler<SamplerWithoutFill>);
static_assert(!Sampler<SamplerWithoutSeed>);
static_assert(!Sampler<SamplerWithMutableDimension>);
static_assert(!Sampler<int>);

// twincal's samplers are interchangeable policies.
static_assert(Sampler<Sobol> && ConstructibleSampler<Sobol>);
static_assert(Sampler<Halton> && ConstructibleSampler<Halton>);
static_assert(Sampler<PseudoRandom> && ConstructibleSampler<PseudoRandom>);
static_assert(Sampler<LatinHypercube> && ConstructibleSampler<LatinHypercube>);

// ConstructibleSampler also needs `Options` and the (dimension, options) constructor.
struct OptionsFreeSampler : CompleteSampler {};
struct WrongConstructorSampler : CompleteSampler {
  struct Options {};
  explicit WrongConstructorSampler(Options) {}
};
static_assert(!ConstructibleSampler<CompleteSampler>);
static_assert(!ConstructibleSampler<OptionsFreeSampler>);
static_assert(Sampler<WrongConstructorSampler> && !ConstructibleSampler<WrongConstructorSampler>);

}  // namespace twincal::static_checks
