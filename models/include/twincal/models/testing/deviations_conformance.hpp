#pragma once
/// @file
/// The conformance suite of a TwinWithDeviations, besides TwinConformance (include it from a
/// test, not from library code; the Case is TwinConformance's):
///
///     namespace twincal::conformance {
///     INSTANTIATE_TYPED_TEST_SUITE_P(Mine, DeviationsConformance, ::testing::Types<MyCase>);
///     }
///
/// What a least-squares search of eq. (3) (controllers' LeastSquaresSearch) relies on, at
/// TwinConformance's controls: Q(x, u) = ‖r(x, u)‖ / √m, to 1e-9 relative (the twin may compute Q
/// another way, e.g. from Q² as a quadratic) plus the Case's tolerance; the deviations are
/// finite inside the bounds; column j of a batch equals the batch of that one control; a batch
/// of the wrong shape throws DimensionMismatchError (require_deviations_batch).

#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>
#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/error.hpp"
#include "twincal/models/testing/twin_conformance.hpp"
#include "twincal/models/twin.hpp"

namespace twincal::conformance {

template <typename Case>
class DeviationsConformance : public TwinConformance<Case> {
 protected:
  using Base = TwinConformance<Case>;
  static_assert(TwinWithDeviations<typename Base::TwinType>,
                "Case::Twin must satisfy twincal::TwinWithDeviations");

  /// The m × k deviations of the controls `u` in one batch.
  static MatrixX deviations(const typename Base::Assembly& assembly, const MatrixX& u) {
    MatrixX out(Base::twin().key_point_count(), u.cols());
    Base::twin().deviations_batch(assembly, u, out);
    return out;
  }
};

TYPED_TEST_SUITE_P(DeviationsConformance);

TYPED_TEST_P(DeviationsConformance, QualityIsTheRmsOfTheDeviations) {
  const MatrixX u = this->controls(11);
  const Index m = this->twin().key_point_count();
  ASSERT_GE(m, 1);
  for (const auto& assembly : this->assemblies()) {
    const MatrixX r = this->deviations(assembly, u);
    const VectorX q = this->batch(assembly, u);
    for (Index j = 0; j < u.cols(); ++j) {
      ASSERT_TRUE(r.col(j).allFinite()) << "control " << j << ": deviations not finite";
      const double rms = r.col(j).norm() / std::sqrt(static_cast<double>(m));
      EXPECT_LE(std::abs(rms - q(j)), (1e-9 + this->tolerance()) * std::max(1.0, q(j)))
          << "control " << j << ": Q " << q(j) << ", RMS of the deviations " << rms;
    }
  }
}

TYPED_TEST_P(DeviationsConformance, EachColumnEqualsTheBatchOfOne) {
  const MatrixX u = this->controls(12);
  for (const auto& assembly : this->assemblies()) {
    const MatrixX whole = this->deviations(assembly, u);
    for (Index j = 0; j < u.cols(); ++j) {
      const MatrixX one = this->deviations(assembly, u.col(j));
      for (Index i = 0; i < whole.rows(); ++i) {
        EXPECT_TRUE(this->same(one(i, 0), whole(i, j)))
            << "control " << j << ", key point " << i << ": " << one(i, 0) << " alone, "
            << whole(i, j) << " in the batch";
      }
    }
  }
}

TYPED_TEST_P(DeviationsConformance, WrongShapesThrowDimensionMismatchError) {
  const auto& twin = this->twin();
  const Index d = twin.control_dimension();
  const Index m = twin.key_point_count();
  const auto assembly = this->assemblies().front();
  const MatrixX centre = (0.5 * (twin.lower_bounds() + twin.upper_bounds())).replicate(1, 2);
  MatrixX rows_short(m - 1, 2);
  EXPECT_THROW(twin.deviations_batch(assembly, centre, rows_short), DimensionMismatchError);
  MatrixX columns_short(m, 1);
  EXPECT_THROW(twin.deviations_batch(assembly, centre, columns_short), DimensionMismatchError);
  MatrixX out(m, 2);
  EXPECT_THROW(twin.deviations_batch(assembly, MatrixX::Zero(d + 1, 2), out),
               DimensionMismatchError);
}

REGISTER_TYPED_TEST_SUITE_P(DeviationsConformance, QualityIsTheRmsOfTheDeviations,
                            EachColumnEqualsTheBatchOfOne, WrongShapesThrowDimensionMismatchError);

}  // namespace twincal::conformance
