#include "twincal/models/exact_optimum_twin.hpp"

#include <cmath>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "twincal/core/error.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/models/analytic_assembly_set.hpp"
#include "twincal/models/twin.hpp"

namespace twincal {
namespace {

/// Q = sqrt(q0) + Σ |u_k − a_k|: the smallest shape with the optimum a(x).
struct AbsoluteShape {
  template <typename A, typename U>
  [[nodiscard]] double quality(double q0, const A& a, const U& control) const {
    return std::sqrt(q0) + (control - a).cwiseAbs().sum();
  }
};

using AbsoluteTwin = ExactOptimumTwin<AbsoluteShape>;
static_assert(TwinWithOptimum<AbsoluteTwin>);

AbsoluteTwin make_absolute_twin() {
  AnalyticAssemblyOptions options;
  options.dimension = 2;
  return {AnalyticAssemblySet(options, RandomStream(5)), AbsoluteShape{}};
}

TEST(ExactOptimumTwin, QualityIsTheShapesAtTheAssemblysParameters) {
  const AbsoluteTwin twin = make_absolute_twin();
  const AssemblyId x{2, 3};
  const VectorX a = twin.optimum(x);
  EXPECT_EQ(a, VectorX(twin.assembly_set().optimum(x)));
  EXPECT_EQ(twin.optimal_quality(x), std::sqrt(twin.assembly_set().q0(x)));
  EXPECT_EQ(twin.quality(x, a), twin.optimal_quality(x));
  const VectorX u = a + VectorX::Constant(2, 0.25);
  EXPECT_DOUBLE_EQ(twin.quality(x, u), twin.optimal_quality(x) + 0.5);
}

TEST(ExactOptimumTwin, TheBatchIsTheQualityOfEachColumn) {
  const AbsoluteTwin twin = make_absolute_twin();
  const AssemblyId x{0, 9};
  MatrixX controls(2, 3);
  controls << 0.1, -0.2, 0.3, 0.0, 0.5, -0.4;
  VectorX out(3);
  twin.quality_batch(x, controls, out);
  for (Index j = 0; j < 3; ++j) {
    EXPECT_EQ(out(j), twin.quality(x, VectorX(controls.col(j)))) << j;
  }
}

TEST(ExactOptimumTwin, ChecksSizesBeforeTheAssembly) {
  const AbsoluteTwin twin = make_absolute_twin();
  EXPECT_THROW((void)twin.quality(AssemblyId{0, 0}, VectorX::Zero(3)), DimensionMismatchError);
  EXPECT_THROW((void)twin.quality(AssemblyId{99, 0}, VectorX::Zero(2)), InvalidArgumentError);
  VectorX out(2);
  EXPECT_THROW(twin.quality_batch(AssemblyId{99, 0}, MatrixX::Zero(2, 3), out),
               DimensionMismatchError);
  EXPECT_THROW(twin.quality_batch(AssemblyId{99, 0}, MatrixX::Zero(2, 2), out),
               InvalidArgumentError);
}

}  // namespace
}  // namespace twincal
