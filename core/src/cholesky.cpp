// The run-time-sized factorization's dispatch to compile-time sizes, and the repairs that
// cholesky.hpp declares `extern`.
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

template CholeskyResult<Dynamic> repaired_cholesky<Dynamic>(const MatrixX&, const CholeskyOptions&,
                                                            std::string_view);
template CholeskyResult<1> repaired_cholesky<1>(const SquareMatrix<1>&, const CholeskyOptions&,
                                                std::string_view);
template CholeskyResult<2> repaired_cholesky<2>(const SquareMatrix<2>&, const CholeskyOptions&,
                                                std::string_view);
template CholeskyResult<3> repaired_cholesky<3>(const SquareMatrix<3>&, const CholeskyOptions&,
                                                std::string_view);
template CholeskyResult<6> repaired_cholesky<6>(const SquareMatrix<6>&, const CholeskyOptions&,
                                                std::string_view);

}  // namespace twincal::detail
