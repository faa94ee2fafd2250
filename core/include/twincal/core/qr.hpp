#pragma once
/// @file
/// Eigen's QR decompositions at run-time size, compiled once. The square-root filters factor
/// with HouseholderQR, the analytic twins draw their random rotations with it and fit their
/// quadratic departure with ColPivHouseholderQR; each factorization (computeInPlace) cost about
/// 2 s of compile time in each of some 20 files that instantiated it. Include this header
/// instead of <Eigen/QR>: the declarations below make those files link the instantiations of
/// core's src/qr.cpp.

#include <Eigen/QR>

#include "twincal/core/eigen.hpp"

extern template class Eigen::HouseholderQR<twincal::MatrixX>;
extern template class Eigen::ColPivHouseholderQR<twincal::MatrixX>;
