// The sampler conformance suite (samplers/testing/sampler_conformance.hpp) for every sampler of
// the module in each of its configurations: the checks every sampler shares live there, the
// golden and sampler-specific tests in <sampler>_test.cpp.
#include "twincal/samplers/testing/sampler_conformance.hpp"

#include <cstdint>

#include <gtest/gtest.h>

#include "twincal/samplers/balance_check.hpp"
#include "twincal/samplers/halton.hpp"
#include "twincal/samplers/latin_hypercube.hpp"
#include "twincal/samplers/pseudo_random.hpp"
#include "twincal/samplers/sobol.hpp"

namespace twincal {
namespace {

// Sobol refuses unbalanced batches, so the suite's batches must all be aligned 2^m blocks.
template <SobolRandomization R>
struct SobolCase {
  using Sampler = Sobol;
  static constexpr Index dimension = 7;
  static constexpr bool is_sequence = true;
  static constexpr bool is_randomized = R != SobolRandomization::none;
  static Sampler make(Index d, std::uint64_t seed) {
    return Sobol(d, {.randomization = R, .seed = seed, .balance = BalanceCheck::refuse});
  }
};
using SobolPlain = SobolCase<SobolRandomization::none>;
using SobolLinearMatrixScramble = SobolCase<SobolRandomization::linear_matrix_scramble>;
using SobolOwen = SobolCase<SobolRandomization::owen>;

template <bool Scramble>
struct HaltonCase {
  using Sampler = Halton;
  static constexpr Index dimension = 6;
  static constexpr bool is_sequence = true;
  static constexpr bool is_randomized = Scramble;
  static Sampler make(Index d, std::uint64_t seed) {
    return Halton(d, {.scramble = Scramble, .seed = seed});
  }
};
using HaltonPlain = HaltonCase<false>;
using HaltonScrambled = HaltonCase<true>;

struct PseudoRandomCase {
  using Sampler = PseudoRandom;
  static constexpr Index dimension = 4;
  static constexpr bool is_sequence = true;
  static constexpr bool is_randomized = true;
  static Sampler make(Index d, std::uint64_t seed) { return PseudoRandom(d, {.seed = seed}); }
};

template <bool Centered>
struct LatinHypercubeCase {
  using Sampler = LatinHypercube;
  static constexpr Index dimension = 5;
  static constexpr bool is_sequence = false;  // every fill is one design
  static constexpr bool is_randomized = true;
  static Sampler make(Index d, std::uint64_t seed) {
    return LatinHypercube(d, {.seed = seed, .centered = Centered});
  }
};
using LatinHypercubeUniform = LatinHypercubeCase<false>;
using LatinHypercubeCentered = LatinHypercubeCase<true>;

using Samplers =
    ::testing::Types<SobolPlain, SobolLinearMatrixScramble, SobolOwen, HaltonPlain, HaltonScrambled,
                     PseudoRandomCase, LatinHypercubeUniform, LatinHypercubeCentered>;

}  // namespace
}  // namespace twincal

namespace twincal::conformance {
INSTANTIATE_TYPED_TEST_SUITE_P(Builtin, SamplerConformance, Samplers);
}  // namespace twincal::conformance
