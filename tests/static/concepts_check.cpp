// Compile-time checks of twincal's concepts: what each accepts and what it rejects. A failing
// static_assert fails the build, naming the requirement.
#include <cstdint>
#include <optional>
#include <string>

#include "twincal/core/options.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/samplers/sampler.hpp"

namespace twincal::static_checks {

// --- Sampler ---------------------------------------------------------------------------------
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
struct SamplerWithMutableDimension {  // dimension() must be callable on a const sampler
  Index dimension() { return 2; }
  void seed(std::uint64_t) {}
  void discard(std::uint64_t) {}
  void fill(Eigen::Ref<MatrixX>) {}
};
static_assert(Sampler<CompleteSampler>);
static_assert(!Sampler<SamplerWithoutDiscard>);
static_assert(!Sampler<SamplerWithoutFill>);
static_assert(!Sampler<SamplerWithMutableDimension>);
static_assert(!Sampler<int>);

// --- ValidatableOptions ----------------------------------------------------------------------
struct GoodOptions {
  [[nodiscard]] std::optional<std::string> validate() const { return std::nullopt; }
};
struct BoolValidate {  // a bool says that something is wrong, not what
  [[nodiscard]] bool validate() const { return true; }
};
static_assert(ValidatableOptions<GoodOptions>);
static_assert(!ValidatableOptions<BoolValidate>);

// --- RandomStream is a standard random bit generator ------------------------------------------
static_assert(std::uniform_random_bit_generator<RandomStream>);

}  // namespace twincal::static_checks
