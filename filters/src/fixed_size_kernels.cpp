// The run-time-sized entry points of fixed_size_kernels.hpp: each maps its run-time-sized
// operands onto compile-time-sized views and runs the kernel's instantiation K = n.
#include "twincal/filters/fixed_size_kernels.hpp"

#include <type_traits>

namespace twincal::kernels {
namespace {

// A column-major n × m operand viewed with K rows (C columns, if known), keeping its column
// stride; read-only when the operand's data is.
template <int K, int C = Dynamic, typename Operand>
auto rows_as(Operand& m) {
  using Scalar = std::remove_pointer_t<decltype(m.data())>;
  using Plain = std::conditional_t<std::is_const_v<Scalar>, const Matrix<K, C>, Matrix<K, C>>;
  using View = Eigen::Map<Plain, Eigen::Unaligned, Eigen::OuterStride<>>;
  return View(m.data(), K, m.cols(), Eigen::OuterStride<>(m.outerStride()));
}

}  // namespace

bool weighted_scatter(const MatrixX& points, const VectorX& weights, const VectorX& centre,
                      MatrixX& out) {
  return dispatch_fixed_size<max_fixed_dispatch_size>(points.rows(), [&]<int K>() {
    Eigen::Map<SquareMatrix<K>> result(out.data());
    weighted_scatter<K>(rows_as<K>(points), weights, Eigen::Map<const Vector<K>>(centre.data()),
                        result);
  });
}

bool cross_covariance(const MatrixX& points, const VectorX& weights, const VectorX& values,
                      double predicted, const VectorX& centre, VectorX& out) {
  return dispatch_fixed_size<max_fixed_dispatch_size>(points.rows(), [&]<int K>() {
    Eigen::Map<Vector<K>> result(out.data());
    cross_covariance<K>(rows_as<K>(points), weights, values, predicted,
                        Eigen::Map<const Vector<K>>(centre.data()), result);
  });
}

bool symmetric_pairs(Eigen::Ref<const VectorX> mean, Eigen::Ref<const MatrixX> lower, double scale,
                     Index first, Eigen::Ref<MatrixX> points) {
  return dispatch_fixed_size<max_fixed_dispatch_size>(mean.size(), [&]<int K>() {
    auto view = rows_as<K>(points);
    symmetric_pairs<K>(Eigen::Map<const Vector<K>>(mean.data()), rows_as<K, K>(lower), scale, first,
                       view);
  });
}

bool quadratic_qualities(const MatrixX& weight, double offset, Eigen::Ref<const VectorX> shift,
                         Eigen::Ref<const MatrixX> states, Eigen::Ref<VectorX> out) {
  return dispatch_fixed_size<max_fixed_dispatch_size>(states.rows(), [&]<int K>() {
    quadratic_qualities<K>(Eigen::Map<const SquareMatrix<K>>(weight.data()), offset,
                           Eigen::Map<const Vector<K>>(shift.data()), rows_as<K>(states), out);
  });
}

}  // namespace twincal::kernels
