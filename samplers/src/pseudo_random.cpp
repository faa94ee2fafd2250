#include "twincal/samplers/pseudo_random.hpp"

#include <limits>

#include <fmt/format.h>

#include "twincal/core/error.hpp"

namespace twincal {

void UniformDraws::discard(RandomStream& stream, const Options& /*options*/, Index dimension,
                           std::uint64_t count) const {
  const auto d = static_cast<std::uint64_t>(dimension);
  if (count > std::numeric_limits<unsigned long long>::max() / d) {
    throw InvalidArgumentError(
        "count", fmt::format("count: value is {}; rule: count · dimension ({}) must fit in 64 bits",
                             count, d));
  }
  stream.discard(count * d);
}

void UniformDraws::fill(RandomStream& stream, const Options& /*options*/,
                        Eigen::Ref<MatrixX> points) const {
  for (Index c = 0; c < points.cols(); ++c) {
    for (Index r = 0; r < points.rows(); ++r) {
      points(r, c) = static_cast<double>(stream() >> 11U) * 0x1p-53;
    }
  }
}

}  // namespace twincal
