#include "twincal/sheet_metal/acm_plate_element.hpp"

#include <gtest/gtest.h>
#include <Eigen/Eigenvalues>

#include "twincal/core/error.hpp"

namespace twincal::acm_plate_element_test {
namespace {

TEST(AcmPlateElement, StiffnessHasExactlyTheThreeRigidModesAsNullSpace) {
  const AcmPlateElement element(30.0, 20.0, PlateSection{});
  const SquareMatrix<12>& k = element.stiffness();
  EXPECT_LT((k - k.transpose()).norm(), 1e-12 * k.norm());
  const Vector<12> lambda = Eigen::SelfAdjointEigenSolver<SquareMatrix<12>>(k).eigenvalues();
  const double largest = lambda(11);
  EXPECT_GT(lambda(0), -1e-10 * largest);
  EXPECT_LT(std::abs(lambda(2)), 1e-10 * largest);
  EXPECT_GT(lambda(3), 1e-8 * largest);
}

TEST(AcmPlateElement, ShapeFunctionsInterpolateTheNodalValues) {
  const AcmPlateElement element(30.0, 20.0, PlateSection{});
  // Corner k, dof w: N_j(corner k) = δ(j, 3k).
  const double corners[4][2] = {{-15.0, -10.0}, {15.0, -10.0}, {15.0, 10.0}, {-15.0, 10.0}};
  for (int k = 0; k < 4; ++k) {
    const RowVector<12> n = element.shape(corners[k][0], corners[k][1]);
    for (int j = 0; j < 12; ++j) EXPECT_NEAR(n(j), j == 3 * k ? 1.0 : 0.0, 1e-12);
  }
  // The consistent load of a unit pressure carries the element's area in its w entries.
  const AcmPlateElement::Load load = element.pressure_load(1.0);
  EXPECT_NEAR(load(0) + load(3) + load(6) + load(9), 600.0, 1e-9);
}

TEST(AcmPlateElement, RejectsBadSizes) {
  EXPECT_THROW(AcmPlateElement(0.0, 1.0, PlateSection{}), InvalidArgumentError);
  PlateSection section;
  section.thickness = -1.0;
  EXPECT_THROW(AcmPlateElement(1.0, 1.0, section), InvalidArgumentError);
}

}  // namespace
}  // namespace twincal::acm_plate_element_test
