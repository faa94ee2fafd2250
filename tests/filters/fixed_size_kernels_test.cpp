#include "twincal/filters/fixed_size_kernels.hpp"

#include <cmath>
#include <utility>

#include <gtest/gtest.h>

namespace twincal {
namespace {

// Operands of size n with distinct, reproducible entries: m points, weights of both signs (as
// Merwe's centre weight can be), a centre, an SPD weight matrix, a shift.
struct KernelOperands {
  explicit KernelOperands(Index n) : n(n) {
    points.resize(n, m);
    weights.resize(m);
    values.resize(m);
    for (Index i = 0; i < m; ++i) {
      weights(i) = i == 0 ? -0.3 : 0.1 + 0.01 * static_cast<double>(i);
      values(i) = std::cos(0.9 * static_cast<double>(i));
      for (Index r = 0; r < n; ++r)
        points(r, i) = std::sin(0.4 + 0.7 * static_cast<double>(r) + 1.1 * static_cast<double>(i));
    }
    centre = VectorX::LinSpaced(n, -0.2, 0.3);
    shift = VectorX::LinSpaced(n, 0.5, -0.1);
    const MatrixX b = points.leftCols(n);
    weight = b * b.transpose() + MatrixX::Identity(n, n);
    lower = weight.llt().matrixL();
  }
  Index n;
  Index m = 11;
  MatrixX points;
  VectorX weights;
  VectorX values;
  VectorX centre;
  VectorX shift;
  MatrixX weight;
  MatrixX lower;
};

// The kernels' definitions, written out over run-time sizes.
MatrixX reference_scatter(const KernelOperands& o) {
  MatrixX sum = MatrixX::Zero(o.n, o.n);
  for (Index i = 0; i < o.m; ++i) {
    const VectorX d = o.points.col(i) - o.centre;
    sum += o.weights(i) * d * d.transpose();
  }
  return sum;
}

VectorX reference_cross_covariance(const KernelOperands& o, double predicted) {
  VectorX sum = VectorX::Zero(o.n);
  for (Index i = 0; i < o.m; ++i) {
    sum += o.weights(i) * (o.values(i) - predicted) * (o.points.col(i) - o.centre);
  }
  return sum;
}

VectorX reference_qualities(const KernelOperands& o, double offset) {
  VectorX out(o.m);
  for (Index i = 0; i < o.m; ++i) {
    const VectorX e = o.shift - o.points.col(i);
    out(i) = std::sqrt(offset + e.dot(o.weight * e));
  }
  return out;
}

TEST(FixedSizeKernels, RunTimeEntryPointsComputeTheDefinitionsUpToTheBound) {
  for (Index n = 1; n <= max_fixed_dispatch_size; ++n) {
    const KernelOperands o(n);
    MatrixX scatter(n, n);
    ASSERT_TRUE(kernels::weighted_scatter(o.points, o.weights, o.centre, scatter));
    EXPECT_TRUE(scatter.isApprox(reference_scatter(o), 1e-14)) << "n = " << n;

    VectorX cross(n);
    ASSERT_TRUE(kernels::cross_covariance(o.points, o.weights, o.values, 0.25, o.centre, cross));
    EXPECT_TRUE(cross.isApprox(reference_cross_covariance(o, 0.25), 1e-14)) << "n = " << n;

    MatrixX pairs = MatrixX::Constant(n, 2 * n + 3, 7.0);
    ASSERT_TRUE(kernels::symmetric_pairs(o.centre, o.lower, 1.5, 2, pairs));
    for (Index k = 0; k < n; ++k) {
      EXPECT_TRUE(pairs.col(2 + k).isApprox(o.centre + 1.5 * o.lower.col(k), 1e-15));
      EXPECT_TRUE(pairs.col(2 + n + k).isApprox(o.centre - 1.5 * o.lower.col(k), 1e-15));
    }
    EXPECT_TRUE((pairs.leftCols(2).array() == 7.0).all()) << "n = " << n;
    EXPECT_TRUE((pairs.col(2 * n + 2).array() == 7.0).all()) << "n = " << n;

    VectorX qualities(o.m);
    ASSERT_TRUE(kernels::quadratic_qualities(o.weight, 0.04, o.shift, o.points, qualities));
    EXPECT_TRUE(qualities.isApprox(reference_qualities(o, 0.04), 1e-14)) << "n = " << n;
  }
}

TEST(FixedSizeKernels, RunTimeEntryPointsDeclineLargerSizesAndTouchNothing) {
  const Index n = max_fixed_dispatch_size + 1;
  const KernelOperands o(n);
  MatrixX scatter = MatrixX::Constant(n, n, 7.0);
  VectorX cross = VectorX::Constant(n, 7.0);
  MatrixX pairs = MatrixX::Constant(n, 2 * n, 7.0);
  VectorX qualities = VectorX::Constant(o.m, 7.0);
  EXPECT_FALSE(kernels::weighted_scatter(o.points, o.weights, o.centre, scatter));
  EXPECT_FALSE(kernels::cross_covariance(o.points, o.weights, o.values, 0.25, o.centre, cross));
  EXPECT_FALSE(kernels::symmetric_pairs(o.centre, o.lower, 1.5, 0, pairs));
  EXPECT_FALSE(kernels::quadratic_qualities(o.weight, 0.04, o.shift, o.points, qualities));
  EXPECT_TRUE((scatter.array() == 7.0).all());
  EXPECT_TRUE((cross.array() == 7.0).all());
  EXPECT_TRUE((pairs.array() == 7.0).all());
  EXPECT_TRUE((qualities.array() == 7.0).all());
}

// The compile-time kernels, as fixed-size filters call them (plain fixed-size operands).
template <int K>
void check_compile_time_kernels() {
  const KernelOperands o(K);
  const Matrix<K, Dynamic> points = o.points;
  const Vector<K> centre = o.centre;
  SquareMatrix<K> scatter;
  kernels::weighted_scatter<K>(points, o.weights, centre, scatter);
  EXPECT_TRUE(MatrixX(scatter).isApprox(reference_scatter(o), 1e-14)) << "K = " << K;
  Vector<K> cross;
  kernels::cross_covariance<K>(points, o.weights, o.values, 0.25, centre, cross);
  EXPECT_TRUE(VectorX(cross).isApprox(reference_cross_covariance(o, 0.25), 1e-14)) << "K = " << K;
  VectorX qualities(o.m);
  kernels::quadratic_qualities<K>(SquareMatrix<K>(o.weight), 0.04, Vector<K>(o.shift), points,
                                  qualities);
  EXPECT_TRUE(qualities.isApprox(reference_qualities(o, 0.04), 1e-14)) << "K = " << K;
}

TEST(FixedSizeKernels, CompileTimeKernelsComputeTheDefinitionsAtEverySize) {
  [&]<int... K>(std::integer_sequence<int, K...>) { (check_compile_time_kernels<K + 1>(), ...); }
  (std::make_integer_sequence<int, max_fixed_dispatch_size>{});
}

}  // namespace
}  // namespace twincal
