// The QR decompositions that qr.hpp declares `extern`.
#include "twincal/core/qr.hpp"

template class Eigen::HouseholderQR<twincal::MatrixX>;
template class Eigen::ColPivHouseholderQR<twincal::MatrixX>;
