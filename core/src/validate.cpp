// The eigenvalue ranges that validate.hpp declares `extern`: compiled once here instead of in
// every file that checks a covariance of these sizes.
#include "twincal/core/validate.hpp"

namespace twincal::detail {

template std::pair<double, double> symmetric_eigenvalue_range<Dynamic>(const MatrixX&);
template std::pair<double, double> symmetric_eigenvalue_range<1>(const SquareMatrix<1>&);
template std::pair<double, double> symmetric_eigenvalue_range<2>(const SquareMatrix<2>&);
template std::pair<double, double> symmetric_eigenvalue_range<3>(const SquareMatrix<3>&);
template std::pair<double, double> symmetric_eigenvalue_range<6>(const SquareMatrix<6>&);

}  // namespace twincal::detail
