#include "twincal/samplers/halton.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <utility>

#include <fmt/format.h>

#include "twincal/core/error.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/core/validate.hpp"

namespace twincal {
namespace {

// The first `count` primes (sieve of Eratosthenes up to Rosser's bound p_n < n (ln n + ln ln n),
// n >= 6).
std::vector<std::uint32_t> first_primes(std::size_t count) {
  const double n = static_cast<double>(std::max<std::size_t>(count, 6));
  const auto bound = static_cast<std::size_t>(n * (std::log(n) + std::log(std::log(n)))) + 1;
  std::vector<bool> composite(bound + 1, false);
  std::vector<std::uint32_t> primes;
  primes.reserve(count);
  for (std::size_t p = 2; p <= bound && primes.size() < count; ++p) {
    if (composite[p]) continue;
    primes.push_back(static_cast<std::uint32_t>(p));
    for (std::size_t q = p * p; q <= bound; q += p) composite[q] = true;
  }
  return primes;
}

}  // namespace

Halton::Halton(Index dimension, HaltonOptions options) : options_(options) {
  if (dimension < 1 || dimension > max_dimension) {
    throw InvalidArgumentError(
        "dimension",
        fmt::format("dimension: value is {}; rule: must lie in [1, {}]", dimension, max_dimension));
  }
  bases_ = first_primes(static_cast<std::size_t>(dimension));
  draw_permutations();
}

void Halton::seed(std::uint64_t value) {
  options_.seed = value;
  draw_permutations();
  position_ = 0;
}

void Halton::discard(std::uint64_t count) {
  if (count > std::numeric_limits<std::uint64_t>::max() - position_) {
    throw InvalidArgumentError(
        "count", fmt::format("count: value is {} at position {}; rule: the point index must fit "
                             "in 64 bits",
                             count, position_));
  }
  position_ += count;
}

void Halton::draw_permutations() {
  digit_count_.clear();
  permutation_offset_.clear();
  permutations_.clear();
  if (!options_.scramble) return;
  RandomStream stream(options_.seed);
  std::size_t total = 0;
  for (const std::uint32_t base : bases_) {
    // SciPy's digit count: the positions a double can resolve, ⌈54 / log2 b⌉ − 1.
    const auto digits =
        static_cast<std::uint32_t>(std::ceil(54.0 / std::log2(static_cast<double>(base)))) - 1;
    digit_count_.push_back(digits);
    permutation_offset_.push_back(total);
    total += std::size_t{digits} * base;
  }
  permutations_.resize(total);
  for (std::size_t j = 0; j < bases_.size(); ++j) {
    const std::uint32_t base = bases_[j];
    for (std::uint32_t i = 0; i < digit_count_[j]; ++i) {
      auto* first = permutations_.data() + permutation_offset_[j] + std::size_t{i} * base;
      std::iota(first, first + base, std::uint32_t{0});
      for (std::uint32_t k = base - 1; k > 0; --k) {  // Fisher–Yates
        std::swap(first[k], first[stream.uniform_int<std::uint32_t>(0, k)]);
      }
    }
  }
}

void Halton::fill(Eigen::Ref<MatrixX> points) {
  require_dimension("points", points.rows(), dimension(), "rows");
  const auto count = static_cast<std::uint64_t>(points.cols());
  if (count > std::numeric_limits<std::uint64_t>::max() - position_) {
    throw InvalidArgumentError(
        "points", fmt::format("points: {} points at position {}; rule: the point index must fit "
                              "in 64 bits",
                              count, position_));
  }
  const double largest_below_one = std::nextafter(1.0, 0.0);
  for (std::size_t j = 0; j < bases_.size(); ++j) {
    const std::uint64_t base = bases_[j];
    const double inverse_base = 1.0 / static_cast<double>(base);
    const auto row = static_cast<Index>(j);
    for (std::uint64_t c = 0; c < count; ++c) {
      // SciPy's recurrence, operation for operation: b2r starts at 1/b and is divided by b.
      std::uint64_t quotient = position_ + c;
      double b2r = inverse_base;
      double value = 0.0;
      if (!options_.scramble) {
        while (quotient > 0) {
          value += static_cast<double>(quotient % base) * b2r;
          b2r /= static_cast<double>(base);
          quotient /= base;
        }
      } else {
        const std::uint32_t* permutation = permutations_.data() + permutation_offset_[j];
        for (std::uint32_t i = 0; i < digit_count_[j]; ++i, permutation += base) {
          value += static_cast<double>(permutation[quotient % base]) * b2r;
          b2r /= static_cast<double>(base);
          quotient /= base;
        }
        // All digits b − 1 sum to 1 − b^-digits, which rounding can push to 1.
        value = std::min(value, largest_below_one);
      }
      points(row, static_cast<Index>(c)) = value;
    }
  }
  position_ += count;
}

}  // namespace twincal
