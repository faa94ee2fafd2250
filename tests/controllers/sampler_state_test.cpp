#include "twincal/controllers/sampler_state.hpp"

#include <cstdint>
#include <string>
#include <type_traits>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "twincal/core/error.hpp"
#include "twincal/samplers/any_sampler.hpp"
#include "twincal/samplers/candidate_sampler.hpp"

namespace twincal {
namespace {

// A sampler restored from a snapshot that went through text draws the saved sampler's next
// points, bit for bit, after draws of uneven sizes (no power-of-two block: restoring is a seek,
// not a draw, so Sobol's balance check has nothing to say).
template <typename S>
class SamplerStateTest : public ::testing::Test {};
using SnapshotSamplers = ::testing::Types<Sobol, Halton, PseudoRandom, LatinHypercube>;
TYPED_TEST_SUITE(SamplerStateTest, SnapshotSamplers);

template <typename S>
S make_state_sampler(std::uint64_t seed) {
  if constexpr (std::is_same_v<S, Sobol>) {
    return Sobol(3, {.randomization = SobolRandomization::linear_matrix_scramble,
                     .seed = seed,
                     .balance = BalanceCheck::refuse});
  } else if constexpr (std::is_same_v<S, Halton>) {
    return Halton(3, {.scramble = true, .seed = seed});
  } else {
    return S(3, {.seed = seed});
  }
}

TYPED_TEST(SamplerStateTest, ASnapshotRestoresThePositionBitForBit) {
  TypeParam original = make_state_sampler<TypeParam>(7);
  MatrixX points(3, 8);
  original.fill(points);
  if constexpr (!std::is_same_v<TypeParam, Sobol>) {
    MatrixX uneven(3, 5);  // Sobol refuses unbalanced batches here
    original.fill(uneven);
  }
  const nlohmann::json snapshot = nlohmann::json::parse(save_sampler(original).dump());
  // Built with another seed: the snapshot's seed is restored with the position.
  TypeParam restored = make_state_sampler<TypeParam>(8);
  restore_sampler(restored, snapshot);
  EXPECT_EQ(save_sampler(restored), snapshot);
  for (int batch = 0; batch < 3; ++batch) {
    MatrixX a(3, 8);
    MatrixX b(3, 8);
    original.fill(a);
    restored.fill(b);
    EXPECT_EQ(a, b) << "batch " << batch;
  }
}

TYPED_TEST(SamplerStateTest, RefusesASnapshotOfAnotherKindOrDimension) {
  TypeParam sampler = make_state_sampler<TypeParam>(7);
  const nlohmann::json saved = save_sampler(sampler);
  nlohmann::json other = saved;
  other["dimension"] = 4;
  EXPECT_THROW(restore_sampler(sampler, other), DimensionMismatchError);
  other = saved;
  other["format"] = "twincal.another_sampler";
  EXPECT_THROW(restore_sampler(sampler, other), InvalidArgumentError);
  other = saved;
  if (other.contains("stream")) {
    other["stream"]["engine"] = "12 34";
    EXPECT_THROW(restore_sampler(sampler, other), InvalidArgumentError);
  } else {
    other.erase("position");
    EXPECT_THROW(restore_sampler(sampler, other), InvalidArgumentError);
  }
  EXPECT_EQ(save_sampler(sampler), saved);
}

TEST(SamplerState, RefusesASobolPositionPastTheSequence) {
  Sobol sampler(2, {.bits = 4});
  nlohmann::json saved = save_sampler(sampler);
  saved["position"] = 17U;
  EXPECT_THROW(restore_sampler(sampler, saved), InvalidArgumentError);
  EXPECT_EQ(sampler.position(), 0U);
  saved["position"] = 16;  // the end of the sequence
  restore_sampler(sampler, saved);
  EXPECT_EQ(sampler.position(), 16U);
}

// AnySampler saves and restores the sampler it wraps, and refuses another kind's snapshot.
TEST(SamplerState, AnySamplerRestoresTheWrappedSamplerBitForBit) {
  for (const CandidateSampler kind :
       {CandidateSampler::sobol, CandidateSampler::halton, CandidateSampler::random,
        CandidateSampler::latin_hypercube}) {
    AnySampler original(kind, 3, 7);
    MatrixX points(3, 5);  // uneven: AnySampler's Sobol does not check the balance
    original.fill(points);
    const nlohmann::json snapshot = nlohmann::json::parse(save_sampler(original).dump());
    AnySampler restored(kind, 3, 8);
    restore_sampler(restored, snapshot);
    EXPECT_EQ(save_sampler(restored), snapshot) << to_string(kind);
    MatrixX a(3, 8);
    MatrixX b(3, 8);
    original.fill(a);
    restored.fill(b);
    EXPECT_EQ(a, b) << to_string(kind);
  }
  AnySampler sobol(CandidateSampler::sobol, 3, 7);
  const nlohmann::json saved = save_sampler(sobol);
  EXPECT_THROW(restore_sampler(sobol, save_sampler(AnySampler(CandidateSampler::halton, 3, 7))),
               InvalidArgumentError);
  EXPECT_EQ(save_sampler(sobol), saved);
}

}  // namespace
}  // namespace twincal
