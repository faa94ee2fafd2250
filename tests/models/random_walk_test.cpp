#include "twincal/models/random_walk.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace twincal {
namespace {

TEST(RandomWalk, PropagatesTheStateUnchanged) {
  const RandomWalk<3> walk = RandomWalk<3>::isotropic(3, 1e-3);
  const Eigen::Vector3d x(0.1, -0.2, 0.3);
  EXPECT_EQ(walk.propagate(x), x);
  EXPECT_EQ(walk.dimension(), 3);
  EXPECT_EQ(walk.process_noise(), Eigen::Matrix3d::Identity() * 1e-3);
}

TEST(RandomWalk, DynamicDimension) {
  const RandomWalk<Dynamic> walk = RandomWalk<Dynamic>::isotropic(12, 1e-3);
  EXPECT_EQ(walk.dimension(), 12);
  EXPECT_EQ(walk.propagate(Eigen::VectorXd::Ones(12)), Eigen::VectorXd::Ones(12));
}

TEST(RandomWalk, RejectsInvalidProcessNoise) {
  EXPECT_THAT([] { (void)RandomWalk<2>::isotropic(2, -1e-3); },
              ::testing::ThrowsMessage<InvalidArgumentError>(
                  "variance: value is -0.001; rule: must be >= 0"));
  EXPECT_THAT(
      [] { (void)RandomWalk<2>::isotropic(3, 1e-3); },
      ::testing::ThrowsMessage<DimensionMismatchError>("dimension: size is 3; rule: must equal 2"));
  Eigen::Matrix2d indefinite;
  indefinite << 1.0, 2.0, 2.0, 1.0;
  EXPECT_THROW(RandomWalk<2>{indefinite}, NotPositiveDefiniteError);
  EXPECT_THROW(RandomWalk<Dynamic>{Eigen::MatrixXd::Zero(2, 3)}, DimensionMismatchError);
}

}  // namespace
}  // namespace twincal
