#pragma once
/// @file
/// `AnySampler`: the candidate sampler of eq. (14) chosen at run time (Sobol with a linear
/// matrix scramble and digital shift — QMCPy's default, the paper's — Halton scrambled, i.i.d.
/// uniform, or Latin hypercube), one Sampler type for the w-controller so a sampler ablation does
/// not multiply the controller's instantiations. One dispatch per batch. `visit` reaches the
/// wrapped sampler, e.g. for the SnapshotSampler hooks in controllers' sampler_state.hpp.

#include <cstdint>
#include <utility>
#include <variant>

#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/samplers/balance_check.hpp"
#include "twincal/samplers/candidate_sampler.hpp"
#include "twincal/samplers/halton.hpp"
#include "twincal/samplers/latin_hypercube.hpp"
#include "twincal/samplers/pseudo_random.hpp"
#include "twincal/samplers/sampler.hpp"
#include "twincal/samplers/sobol.hpp"

namespace twincal {

class AnySampler {
 public:
  /// A `kind` sampler of `dimension` coordinates randomized by `seed`. Sobol does not check the
  /// power-of-two balance of its batches: a budget that is not 2^m is the user's ablation.
  /// @throws InvalidArgumentError for a dimension the sampler does not support.
  AnySampler(CandidateSampler kind, Index dimension, std::uint64_t seed)
      : sampler_(make(kind, dimension, seed)) {}

  [[nodiscard]] Index dimension() const {
    return std::visit([](const auto& s) { return static_cast<Index>(s.dimension()); }, sampler_);
  }
  void seed(std::uint64_t value) {
    std::visit([value](auto& s) { s.seed(value); }, sampler_);
  }
  void discard(std::uint64_t count) {
    std::visit([count](auto& s) { s.discard(count); }, sampler_);
  }
  void fill(Eigen::Ref<MatrixX> points) {
    std::visit([&points](auto& s) { s.fill(points); }, sampler_);
  }

  /// `f(sampler)` on the wrapped sampler (a Sobol, Halton, PseudoRandom or LatinHypercube).
  template <typename F>
  decltype(auto) visit(F&& f) const {
    return std::visit(std::forward<F>(f), sampler_);
  }
  template <typename F>
  decltype(auto) visit(F&& f) {
    return std::visit(std::forward<F>(f), sampler_);
  }

 private:
  using Variant = std::variant<Sobol, Halton, PseudoRandom, LatinHypercube>;

  static Variant make(CandidateSampler kind, Index dimension, std::uint64_t seed) {
    switch (kind) {
      case CandidateSampler::halton:
        return Halton(dimension, {.scramble = true, .seed = seed});
      case CandidateSampler::random:
        return PseudoRandom(dimension, {.seed = seed});
      case CandidateSampler::latin_hypercube:
        return LatinHypercube(dimension, {.seed = seed});
      case CandidateSampler::sobol:
        break;
    }
    return Sobol(dimension, {.randomization = SobolRandomization::linear_matrix_scramble,
                             .seed = seed,
                             .balance = BalanceCheck::ignore});
  }

  Variant sampler_;
};

static_assert(Sampler<AnySampler>);

}  // namespace twincal
