#pragma once
/// @file
/// `ExactOptimumTwin<Shape>`: an analytic twin whose optimum is its assemblies' own, u0(x) = a(x)
/// with z*(x) = sqrt(q0(x)), and whose Q is its Shape policy's function of q0(x), a(x) and u.
/// RmsQuadraticTwin (RmsQuadraticShape) and RuggedTwin (RuggedShape) are such twins: the shape is
/// all they add, and the checks, the batch loop and the optimum are written once here.

#include <cmath>
#include <concepts>
#include <utility>

#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/models/analytic_assembly_set.hpp"
#include "twincal/models/analytic_twin_base.hpp"
#include "twincal/models/assembly_id.hpp"
#include "twincal/models/twin.hpp"

namespace twincal {

/// An analytic twin with Q(x, u) = shape.quality(q0(x), a(x), u) (see the file comment). The
/// shape must give sqrt(q0) at u = a and more elsewhere, so that a(x) is the optimum.
template <typename Shape>
requires requires(const Shape& shape, double q0, const MatrixX::ConstColXpr& a,
                  const Eigen::Ref<const VectorX>& control,
                  const Eigen::Ref<const MatrixX>::ConstColXpr& column) {
  { shape.quality(q0, a, control) } -> std::same_as<double>;
  { shape.quality(q0, a, column) } -> std::same_as<double>;
}
class ExactOptimumTwin : public AnalyticTwinBase {
 public:
  ExactOptimumTwin(AnalyticAssemblySet assemblies, Shape shape)
      : AnalyticTwinBase(std::move(assemblies)), shape_(std::move(shape)) {}

  /// Q(x, u).
  /// @throws InvalidArgumentError for an unknown assembly, DimensionMismatchError for a control
  ///         of the wrong size.
  [[nodiscard]] double quality(const AssemblyId& assembly,
                               const Eigen::Ref<const VectorX>& control) const {
    require_control(control, control_dimension());
    return shape_.quality(assembly_set().q0(assembly), assembly_set().optimum(assembly), control);
  }

  /// out(j) = Q(x, controls.col(j)).
  void quality_batch(const AssemblyId& assembly, const Eigen::Ref<const MatrixX>& controls,
                     Eigen::Ref<VectorX> out) const {
    require_control_batch(controls, out, control_dimension());
    const double q0 = assembly_set().q0(assembly);
    const MatrixX::ConstColXpr a = assembly_set().optimum(assembly);
    for (Index j = 0; j < controls.cols(); ++j) out(j) = shape_.quality(q0, a, controls.col(j));
  }

  /// u0(x) = a(x) (eq. 3).
  [[nodiscard]] VectorX optimum(const AssemblyId& assembly) const {
    return assembly_set().optimum(assembly);
  }

  /// z*(x) = Q(x, u0(x)) = sqrt(q0(x)).
  [[nodiscard]] double optimal_quality(const AssemblyId& assembly) const {
    return std::sqrt(assembly_set().q0(assembly));
  }

  [[nodiscard]] const Shape& shape() const noexcept { return shape_; }

 private:
  Shape shape_;
};

}  // namespace twincal
