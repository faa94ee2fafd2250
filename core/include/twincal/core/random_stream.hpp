#pragma once
/// @file
/// `RandomStream`: a seeded, splittable source of random numbers.
///
/// Reproducibility contract. Every random quantity in twincal comes from a RandomStream whose
/// seed derives deterministically from one user seed through named substreams, e.g.
///
///     RandomStream root{seed};                                  // recorded with results
///     RandomStream run = root.substream("run").substream(r);    // run r: same for all controllers
///     RandomStream order = run.substream("assembly_order");
///     RandomStream noise = run.substream("measurement_noise");
///     RandomStream ctrl = run.substream("controller").substream(c);   // controller c's own
///
/// A substream's seed is SplitMix64(SplitMix64(parent seed) XOR key), the key being the 64-bit
/// FNV-1a hash of the label or SplitMix64 of the index, so streams are independent of the order
/// in which they are created and of how many numbers any other stream drew. The engine is
/// std::mt19937_64 (fully specified by the C++ standard) and the distributions are Boost.Random's
/// (header-defined), so the same seed gives the same numbers on every platform and compiler.

#include <cstdint>
#include <limits>
#include <string_view>

#include <Eigen/Core>
#include <boost/random/normal_distribution.hpp>
#include <boost/random/uniform_01.hpp>
#include <boost/random/uniform_int_distribution.hpp>
#include <random>

#include "twincal/core/eigen.hpp"

namespace twincal {

/// SplitMix64 finalizer (Steele, Lea & Flood 2014): a bijective 64-bit mix.
[[nodiscard]] constexpr std::uint64_t splitmix64(std::uint64_t x) noexcept {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30U)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27U)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31U);
}

/// 64-bit FNV-1a hash of a label.
[[nodiscard]] constexpr std::uint64_t fnv1a64(std::string_view label) noexcept {
  std::uint64_t hash = 0xcbf29ce484222325ULL;
  for (const char c : label) {
    hash ^= static_cast<unsigned char>(c);
    hash *= 0x100000001b3ULL;
  }
  return hash;
}

/// A seeded random stream; satisfies std::uniform_random_bit_generator.
class RandomStream {
 public:
  using Engine = std::mt19937_64;
  using result_type = Engine::result_type;

  explicit RandomStream(std::uint64_t seed) : seed_(seed), engine_(seed) {}

  /// The seed this stream started from (record it with results).
  [[nodiscard]] std::uint64_t seed() const noexcept { return seed_; }

  /// An independent stream named `label`, derived from this stream's seed (not its position).
  [[nodiscard]] RandomStream substream(std::string_view label) const {
    return RandomStream(derive(fnv1a64(label)));
  }

  /// An independent stream number `index` (runs, controllers, replicates).
  [[nodiscard]] RandomStream substream(std::uint64_t index) const {
    return RandomStream(derive(splitmix64(index)));
  }

  static constexpr result_type min() noexcept { return Engine::min(); }
  static constexpr result_type max() noexcept { return Engine::max(); }
  result_type operator()() { return engine_(); }

  /// Skips `count` raw draws.
  void discard(unsigned long long count) { engine_.discard(count); }

  /// U[0, 1).
  [[nodiscard]] double uniform() { return boost::random::uniform_01<double>{}(engine_); }

  /// N(0, 1).
  [[nodiscard]] double normal() { return boost::random::normal_distribution<double>{}(engine_); }

  /// Uniform integer in [low, high].
  template <typename Int>
  [[nodiscard]] Int uniform_int(Int low, Int high) {
    return boost::random::uniform_int_distribution<Int>{low, high}(engine_);
  }

  /// Fills `out` with independent N(0, 1) draws, column by column.
  template <typename Derived>
  void fill_normal(Eigen::DenseBase<Derived>& out) {
    for (Index c = 0; c < out.cols(); ++c) {
      for (Index r = 0; r < out.rows(); ++r) out(r, c) = normal();
    }
  }

  /// The underlying engine, for distributions that take one.
  [[nodiscard]] Engine& engine() noexcept { return engine_; }
  /// The engine as it is, e.g. to save its state with `operator<<` (controller snapshots).
  [[nodiscard]] const Engine& engine() const noexcept { return engine_; }

 private:
  [[nodiscard]] std::uint64_t derive(std::uint64_t key) const noexcept {
    return splitmix64(splitmix64(seed_) ^ key);
  }

  std::uint64_t seed_;
  Engine engine_;
};

static_assert(std::uniform_random_bit_generator<RandomStream>);

}  // namespace twincal
