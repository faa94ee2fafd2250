#include "twincal/samplers/sobol.hpp"

#include <bit>
#include <cmath>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "twincal/core/error.hpp"
#include "twincal/core/options.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/core/validate.hpp"
#include "twincal/samplers/sobol_direction_numbers.hpp"

namespace twincal {
namespace {

// x < 2^52 as a double, exactly: 2^52 + x has x as its mantissa. Unlike a uint64 → double
// conversion this vectorizes without AVX-512.
[[nodiscard]] inline double exact_to_double(std::uint64_t x) noexcept {
  return std::bit_cast<double>(0x4330000000000000ULL | x) - 0x1p52;
}

// Unscrambled direction numbers v_0 … v_(bits−1) of coordinate j (0-based), v_i = m_(i+1) ·
// 2^(bits−1−i), into out[i * stride] (Joe & Kuo's recurrence beyond the initial numbers).
void plain_directions(Index j, int bits, std::uint64_t* out, std::size_t stride) {
  const auto b = static_cast<unsigned>(bits);
  if (j == 0) {  // van der Corput: m_i = 1
    for (unsigned i = 0; i < b; ++i) out[i * stride] = std::uint64_t{1} << (b - 1 - i);
    return;
  }
  const sobol_table::SobolPrimitive& p =
      sobol_table::primitive_polynomials()[static_cast<std::size_t>(j - 1)];
  const std::span<const std::uint32_t> m =
      sobol_table::initial_direction_numbers().subspan(p.offset, p.degree);
  const unsigned s = p.degree;
  const auto v = [out, stride](unsigned i) -> std::uint64_t& { return out[i * stride]; };
  for (unsigned i = 0; i < b; ++i) {
    if (i < s) {
      v(i) = std::uint64_t{m[i]} << (b - 1 - i);
      continue;
    }
    std::uint64_t value = v(i - s) ^ (v(i - s) >> s);
    for (unsigned k = 1; k < s; ++k) {
      if ((p.polynomial >> (s - 1 - k)) & 1U) value ^= v(i - k);
    }
    v(i) = value;
  }
}

}  // namespace

std::optional<std::string> SobolOptions::validate() const {
  return rule::check(bits >= 1 && bits <= Sobol::max_bits, "bits", bits,
                     "must lie in [1, {}] so that every point is an exact double", Sobol::max_bits);
}

Sobol::Sobol(Index dimension, SobolOptions options)
    : dimension_(dimension), options_(std::move(options)) {
  require_valid("options", options_);
  if (dimension < 1 || dimension > max_dimension) {
    throw InvalidArgumentError("dimension",
                               fmt::format("dimension: value is {}; rule: must lie in [1, {}] "
                                           "(Joe & Kuo's direction numbers)",
                                           dimension, max_dimension));
  }
  scale_ = std::ldexp(1.0, -options_.bits);
  randomize();
  jump_to(0);
}

void Sobol::seed(std::uint64_t value) {
  options_.seed = value;
  randomize();
  jump_to(0);
}

void Sobol::discard(std::uint64_t count) {
  if (count == 0) return;
  require_available("count", count);
  check_balance(options_.balance, options_.warning_handler, "count", "Sobol discard", position_,
                count);
  jump_to(position_ + count);
}

void Sobol::seek(std::uint64_t position) {
  if (position > size()) {
    throw InvalidArgumentError(
        "position", fmt::format("position: is {}; rule: must be <= the sequence's {} points "
                                "(bits = {})",
                                position, size(), options_.bits));
  }
  jump_to(position);
}

std::uint64_t Sobol::direction(Index j, int i) const {
  require_in_range("j", static_cast<double>(j), 0.0, static_cast<double>(dimension_ - 1));
  require_in_range("i", static_cast<double>(i), 0.0, static_cast<double>(options_.bits - 1));
  return directions_[static_cast<std::size_t>(i) * static_cast<std::size_t>(dimension_) +
                     static_cast<std::size_t>(j)];
}

void Sobol::require_available(std::string_view argument, std::uint64_t count) const {
  if (count <= size() - position_) return;
  throw InvalidArgumentError(
      std::string(argument),
      fmt::format("{}: {} points from position {} pass the end of the sequence; rule: a Sobol "
                  "sequence with bits = {} has {} points",
                  argument, count, position_, options_.bits, size()));
}

void Sobol::randomize() {
  const auto d = static_cast<std::size_t>(dimension_);
  const auto b = static_cast<unsigned>(options_.bits);
  directions_.assign(b * d, 0);
  for (Index j = 0; j < dimension_; ++j) {
    plain_directions(j, options_.bits, directions_.data() + j, d);
  }
  shift_.assign(d, 0);
  owen_keys_.clear();
  RandomStream stream(options_.seed);
  const std::uint64_t all = (std::uint64_t{1} << b) - 1;  // b <= 52
  switch (options_.randomization) {
    case SobolRandomization::none:
      break;
    case SobolRandomization::linear_matrix_scramble: {
      // Output digit k (k = 0 most significant, at bit b−1−k) = XOR of input digits l <= k
      // selected by row k of a random unit lower-triangular matrix: rows[k] holds that row as a
      // bit mask, so the digit is the parity of (v & rows[k]).
      std::vector<std::uint64_t> rows(b);
      for (std::size_t j = 0; j < d; ++j) {
        for (unsigned k = 0; k < b; ++k) {
          const std::uint64_t higher = all & ~((std::uint64_t{1} << (b - k)) - 1);
          rows[k] = (std::uint64_t{1} << (b - 1 - k)) | (stream() & higher);
        }
        for (unsigned i = 0; i < b; ++i) {
          std::uint64_t& v = directions_[i * d + j];
          std::uint64_t scrambled = 0;
          for (unsigned k = 0; k < b; ++k) {
            scrambled |= static_cast<std::uint64_t>(std::popcount(v & rows[k]) & 1) << (b - 1 - k);
          }
          v = scrambled;
        }
        shift_[j] = stream() & all;
      }
      break;
    }
    case SobolRandomization::owen:
      owen_keys_.resize(d);
      for (std::uint64_t& key : owen_keys_) key = stream();
      break;
  }
}

void Sobol::jump_to(std::uint64_t position) {
  const auto d = static_cast<std::size_t>(dimension_);
  state_ = shift_;
  const std::uint64_t gray = position ^ (position >> 1U);
  for (unsigned i = 0; i < static_cast<unsigned>(options_.bits); ++i) {
    if (((gray >> i) & 1U) == 0) continue;
    const std::uint64_t* v = directions_.data() + i * d;
    for (std::size_t j = 0; j < d; ++j) state_[j] ^= v[j];
  }
  position_ = position;
}

std::uint64_t Sobol::owen_scramble(std::uint64_t x, std::uint64_t key) const noexcept {
  // Level k flips digit k by a random bit of the node (k, first k digits); the node id
  // (1 << k) | prefix is unique across levels. Flips are decided on the input digits, which
  // is Owen's nested scrambling: equal prefixes share their permutations.
  const auto b = static_cast<unsigned>(options_.bits);
  std::uint64_t result = x;
  for (unsigned k = 0; k < b; ++k) {
    const std::uint64_t node = (std::uint64_t{1} << k) | (x >> (b - k));
    result ^= (splitmix64(key ^ node) >> 63U) << (b - 1 - k);
  }
  return result;
}

void Sobol::fill(Eigen::Ref<MatrixX> points) {
  require_dimension("points", points.rows(), dimension_, "rows");
  const auto count = static_cast<std::uint64_t>(points.cols());
  if (count == 0) return;
  require_available("points", count);
  check_balance(options_.balance, options_.warning_handler, "points", "Sobol fill", position_,
                count);
  const auto d = static_cast<std::size_t>(dimension_);
  const double scale = scale_;
  std::uint64_t* state = state_.data();
  const bool owen = options_.randomization == SobolRandomization::owen;
  for (std::uint64_t c = 0; c < count; ++c) {
    double* out = &points(0, static_cast<Index>(c));
    if (owen) {
      for (std::size_t j = 0; j < d; ++j) {
        out[j] = exact_to_double(owen_scramble(state[j], owen_keys_[j])) * scale;
      }
    } else {
      for (std::size_t j = 0; j < d; ++j) out[j] = exact_to_double(state[j]) * scale;
    }
    ++position_;
    if (position_ == size()) break;  // the last point: no successor to step to
    // Gray code: point k and k − 1 differ by direction ctz(k).
    const std::uint64_t* v =
        directions_.data() + static_cast<std::size_t>(std::countr_zero(position_)) * d;
    for (std::size_t j = 0; j < d; ++j) state[j] ^= v[j];
  }
}

}  // namespace twincal
