// The run-time-sized factorization's dispatch to compile-time sizes (cholesky.hpp).
#include "twincal/core/cholesky.hpp"

#include "twincal/core/fixed_size_dispatch.hpp"

namespace twincal::detail {

std::optional<bool> fixed_size_factor_lower(const MatrixX& matrix, MatrixX& lower) {
  std::optional<bool> factored;
  dispatch_fixed_size<max_fixed_dispatch_size>(matrix.rows(), [&]<int K>() {
    Eigen::Map<SquareMatrix<K>> fixed(lower.data());
    factored = factor_lower(Eigen::Map<const SquareMatrix<K>>(matrix.data()), fixed);
  });
  return factored;
}

}  // namespace twincal::detail
