#include "twincal/samplers/latin_hypercube.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <utility>

namespace twincal {

void LatinHypercubeDesigns::discard(RandomStream& stream, const Options& options, Index dimension,
                                    std::uint64_t count) {
  if (count == 0) return;
  MatrixX design(dimension, static_cast<Index>(count));
  fill(stream, options, design);
}

void LatinHypercubeDesigns::fill(RandomStream& stream, const Options& options,
                                 Eigen::Ref<MatrixX> points) {
  const Index dimension = points.rows();
  const Index n = points.cols();
  if (n == 0) return;
  const double width = 1.0 / static_cast<double>(n);
  const double largest_below_one = std::nextafter(1.0, 0.0);
  permutation_.resize(static_cast<std::size_t>(n));
  for (Index r = 0; r < dimension; ++r) {
    std::iota(permutation_.begin(), permutation_.end(), Index{0});
    for (Index i = n - 1; i > 0; --i) {  // Fisher–Yates
      const auto k = stream.uniform_int<Index>(0, i);
      std::swap(permutation_[static_cast<std::size_t>(i)],
                permutation_[static_cast<std::size_t>(k)]);
    }
    for (Index c = 0; c < n; ++c) {
      const double offset = options.centered ? 0.5 : stream.uniform();
      // (n − 1 + u)/n with u just below 1 rounds to 1; keep the point in its half-open cell.
      points(r, c) = std::min(
          (static_cast<double>(permutation_[static_cast<std::size_t>(c)]) + offset) * width,
          largest_below_one);
    }
  }
}

}  // namespace twincal
