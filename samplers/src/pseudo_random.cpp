#include "twincal/samplers/pseudo_random.hpp"

#include <limits>

#include <fmt/format.h>

#include "twincal/core/error.hpp"
#include "twincal/core/validate.hpp"

namespace twincal {

PseudoRandom::PseudoRandom(Index dimension, PseudoRandomOptions options)
    : dimension_(dimension), options_(options), stream_(options.seed) {
  if (dimension < 1) {
    throw InvalidArgumentError(
        "dimension", fmt::format("dimension: value is {}; rule: must be >= 1", dimension));
  }
}

void PseudoRandom::seed(std::uint64_t value) {
  options_.seed = value;
  stream_ = RandomStream(value);
}

void PseudoRandom::discard(std::uint64_t count) {
  const auto d = static_cast<std::uint64_t>(dimension_);
  if (count > std::numeric_limits<unsigned long long>::max() / d) {
    throw InvalidArgumentError(
        "count", fmt::format("count: value is {}; rule: count · dimension ({}) must fit in 64 bits",
                             count, d));
  }
  stream_.discard(count * d);
}

void PseudoRandom::fill(Eigen::Ref<MatrixX> points) {
  require_dimension("points", points.rows(), dimension_, "rows");
  for (Index c = 0; c < points.cols(); ++c) {
    for (Index r = 0; r < dimension_; ++r) {
      points(r, c) = static_cast<double>(stream_() >> 11U) * 0x1p-53;
    }
  }
}

}  // namespace twincal
