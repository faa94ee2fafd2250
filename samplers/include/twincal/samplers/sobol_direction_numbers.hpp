#pragma once
/// @file
/// Joe & Kuo's Sobol direction numbers (new-joe-kuo-6.21201, search criterion D6) compiled into
/// the library: S. Joe and F. Y. Kuo, "Constructing Sobol sequences with better two-dimensional
/// projections", SIAM J. Sci. Comput. 30 (2008) 2635–2654; BSD-style licence by the authors
/// (samplers/data/README.md). The table is generated at build time from samplers/data/ by
/// samplers/tools/sobol_table_generator.cpp.

#include <cstdint>
#include <span>

namespace twincal::sobol_table {

/// Number of dimensions covered (dimension 1, the van der Corput sequence, is implicit).
inline constexpr std::uint32_t max_dimension = 21201;

/// Primitive polynomial of one dimension d >= 2: x^s + a_1 x^(s−1) + … + a_(s−1) x + 1 with
/// `polynomial` = the bits a_1 … a_(s−1) (a_1 most significant), and the initial direction
/// numbers m_1 … m_s at initial_direction_numbers()[offset …].
struct SobolPrimitive {
  std::uint32_t degree;      ///< s
  std::uint32_t polynomial;  ///< a, the interior coefficients
  std::uint32_t offset;      ///< index of m_1 in initial_direction_numbers()
};

/// Polynomials of dimensions 2 … max_dimension (entry i is dimension i + 2).
[[nodiscard]] std::span<const SobolPrimitive> primitive_polynomials() noexcept;

/// All initial direction numbers m_k, concatenated dimension by dimension.
[[nodiscard]] std::span<const std::uint32_t> initial_direction_numbers() noexcept;

}  // namespace twincal::sobol_table
