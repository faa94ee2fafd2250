#pragma once
/// @file
/// `RandomStreamSampler<Draws>`: a Sampler whose points come from one RandomStream, the stream
/// being its whole state (PseudoRandom, LatinHypercube). It holds what such samplers share —
/// the checked dimension, the options carrying the seed, seeding, and the stream that
/// controller snapshots save and restore — so the Draws policy only says how points come from
/// the stream: its `Options` aggregate (with a `seed`), `fill` and `discard`.

#include <concepts>
#include <cstdint>

#include <fmt/format.h>
#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/core/validate.hpp"

namespace twincal {

/// A Sampler drawing from one RandomStream (see the file comment).
template <typename Draws>
requires std::default_initializable<Draws> &&
    requires(Draws& draws, const typename Draws::Options& options, RandomStream& stream,
             Index dimension, std::uint64_t count, Eigen::Ref<MatrixX> points) {
  { options.seed } -> std::convertible_to<std::uint64_t>;
  draws.fill(stream, options, points);
  draws.discard(stream, options, dimension, count);
}
class RandomStreamSampler {
 public:
  using Options = typename Draws::Options;

  /// Throws InvalidArgumentError unless dimension >= 1.
  explicit RandomStreamSampler(Index dimension, Options options = {})
      : dimension_(dimension), options_(options), stream_(options.seed) {
    if (dimension < 1) {
      throw InvalidArgumentError(
          "dimension", fmt::format("dimension: value is {}; rule: must be >= 1", dimension));
    }
  }

  [[nodiscard]] Index dimension() const noexcept { return dimension_; }
  [[nodiscard]] const Options& options() const noexcept { return options_; }

  /// Restarts the stream from `value` (stored as options().seed).
  void seed(std::uint64_t value) {
    options_.seed = value;
    stream_ = RandomStream(value);
  }
  /// Skips `count` points the way Draws says.
  void discard(std::uint64_t count) { draws_.discard(stream_, options_, dimension_, count); }
  /// Fills the d × count matrix with the next count points. Throws DimensionMismatchError unless
  /// rows == dimension().
  void fill(Eigen::Ref<MatrixX> points) {
    require_dimension("points", points.rows(), dimension_, "rows");
    draws_.fill(stream_, options_, points);
  }

  /// The stream the points come from: the sampler's whole state (controller snapshots save it).
  [[nodiscard]] const RandomStream& stream() const noexcept { return stream_; }
  /// Continues from `stream`, a stream() saved earlier: the next points are the ones the saved
  /// sampler would have drawn. options().seed becomes the stream's seed.
  void set_stream(const RandomStream& stream) {
    options_.seed = stream.seed();
    stream_ = stream;
  }

 private:
  Index dimension_;
  Options options_;
  RandomStream stream_;
  Draws draws_;
};

}  // namespace twincal
