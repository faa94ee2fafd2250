#include "twincal/samplers/sobol_direction_numbers.hpp"

#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

namespace twincal {
namespace {

std::vector<std::uint32_t> initial_numbers(std::size_t dimension) {
  const auto& p = sobol_table::primitive_polynomials()[dimension - 2];
  const auto m = sobol_table::initial_direction_numbers().subspan(p.offset, p.degree);
  return {m.begin(), m.end()};
}

TEST(SobolDirectionNumbers, CoversAllJoeKuoDimensions) {
  EXPECT_EQ(sobol_table::primitive_polynomials().size(), sobol_table::max_dimension - 1);
  // First and last lines of new-joe-kuo-6.21201.
  const auto& second = sobol_table::primitive_polynomials()[0];
  EXPECT_EQ(second.degree, 1U);
  EXPECT_EQ(second.polynomial, 0U);
  EXPECT_EQ(initial_numbers(2), (std::vector<std::uint32_t>{1}));
  EXPECT_EQ(initial_numbers(5), (std::vector<std::uint32_t>{1, 1, 1}));
  const auto& last = sobol_table::primitive_polynomials().back();
  EXPECT_EQ(last.degree, 18U);
  EXPECT_EQ(last.polynomial, 131059U);
  EXPECT_EQ(initial_numbers(21201),
            (std::vector<std::uint32_t>{1, 1, 7, 11, 15, 7, 37, 239, 337, 245, 1557, 3681, 7357,
                                        9639, 27367, 26869, 114603, 86317}));
}

TEST(SobolDirectionNumbers, EveryEntryIsWellFormed) {
  std::uint32_t offset = 0;
  for (const auto& p : sobol_table::primitive_polynomials()) {
    ASSERT_GE(p.degree, 1U);
    ASSERT_LT(p.polynomial, 1U << (p.degree - 1));
    ASSERT_EQ(p.offset, offset);
    const auto m = sobol_table::initial_direction_numbers().subspan(p.offset, p.degree);
    for (std::uint32_t k = 0; k < p.degree; ++k) {
      ASSERT_EQ(m[k] % 2, 1U);   // odd
      ASSERT_LT(m[k], 2U << k);  // m_(k+1) < 2^(k+1)
    }
    offset += p.degree;
  }
  EXPECT_EQ(offset, sobol_table::initial_direction_numbers().size());
}

}  // namespace
}  // namespace twincal
