#include "twincal/models/key_point_twin.hpp"

#include <cmath>

#include <gtest/gtest.h>

#include "twincal/core/error.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/models/contact_nonlinearity.hpp"
#include "twincal/models/kink_nonlinearity.hpp"
#include "twincal/models/no_nonlinearity.hpp"
#include "twincal/models/quadratic_departure.hpp"
#include "twincal/models/stiffening_nonlinearity.hpp"

namespace twincal::key_point_twin_test {
namespace {

KeyPointTwinOptions options_with(Index d, double strength) {
  KeyPointTwinOptions options;
  options.assemblies.dimension = d;
  options.strength = strength;
  return options;
}

// One suite over every nonlinearity: what every KeyPointTwin must satisfy.
template <typename Kind>
class KeyPointTwinTyped : public ::testing::Test {};
using Kinds =
    ::testing::Types<NoNonlinearity, ContactNonlinearity, StiffeningNonlinearity, KinkNonlinearity>;
TYPED_TEST_SUITE(KeyPointTwinTyped, Kinds);

TYPED_TEST(KeyPointTwinTyped, QualityIsTheRmsOfTheDeviationsAndTheBatchMatches) {
  const KeyPointTwin<TypeParam> twin(options_with(4, 1.0), RandomStream(11));
  static_assert(Twin<KeyPointTwin<TypeParam>>);
  const AssemblyId x{3, 7};
  RandomStream draws(5);
  MatrixX controls(4, 9);
  for (double& u : controls.reshaped()) u = 2.0 * draws.uniform() - 1.0;
  VectorX batch(9);
  twin.quality_batch(x, controls, batch);
  for (Index j = 0; j < controls.cols(); ++j) {
    const VectorX r = twin.deviations(x, controls.col(j));
    ASSERT_EQ(r.size(), 60);
    const double rms = std::sqrt(r.squaredNorm() / 60.0);
    EXPECT_DOUBLE_EQ(twin.quality(x, controls.col(j)), rms);
    EXPECT_DOUBLE_EQ(batch(j), rms);
  }
}

TYPED_TEST(KeyPointTwinTyped, TheSameSeedGivesTheSameTwin) {
  const KeyPointTwin<TypeParam> a(options_with(3, 0.5), RandomStream(4));
  const KeyPointTwin<TypeParam> b(options_with(3, 0.5), RandomStream(4));
  const KeyPointTwin<TypeParam> c(options_with(3, 0.5), RandomStream(5));
  const VectorX u = VectorX::Constant(3, 0.3);
  EXPECT_EQ(a.quality({1, 2}, u), b.quality({1, 2}, u));
  EXPECT_NE(a.quality({1, 2}, u), c.quality({1, 2}, u));
}

TYPED_TEST(KeyPointTwinTyped, ZeroStrengthIsTheQuadraticTwin) {
  const KeyPointTwin<TypeParam> twin(options_with(3, 0.0), RandomStream(8));
  const AssemblyId x{0, 4};
  const VectorX a = twin.assembly_set().optimum(x);
  const MatrixX h = twin.influence().transpose() * twin.influence() / 60.0;
  const VectorX u = VectorX::Constant(3, -0.4);
  const VectorX e = u - a;
  EXPECT_NEAR(twin.quality(x, u), std::sqrt(twin.assembly_set().q0(x) + e.dot(h * e)), 1e-12);
  EXPECT_NEAR(twin.quality(x, a), std::sqrt(twin.assembly_set().q0(x)), 1e-12);
  EXPECT_LT(quadratic_departure(twin, x, a, RandomStream(1)), 1e-9);
}

TEST(KeyPointTwin, TheInfluenceHasTheCurvaturesAskedFor) {
  KeyPointTwinOptions options = options_with(5, 1.0);
  options.min_curvature = 0.7;
  options.max_curvature = 3.0;
  const KeyPointTwin<NoNonlinearity> twin(options, RandomStream(2));
  const MatrixX h = twin.influence().transpose() * twin.influence() / 60.0;
  const Eigen::SelfAdjointEigenSolver<MatrixX> eigen(h);
  EXPECT_GE(eigen.eigenvalues().minCoeff(), 0.7 - 1e-12);
  EXPECT_LE(eigen.eigenvalues().maxCoeff(), 3.0 + 1e-12);
}

// At strength 1 every nonlinearity makes Q² depart from a quadratic by several per cent, so
// a controller that assumes a quadratic is tested on something that is not one.
TEST(KeyPointTwin, NonlinearitiesDepartFromAQuadraticAtStrengthOne) {
  const AssemblyId x{2, 2};
  const KeyPointTwin<ContactNonlinearity> contact(options_with(3, 1.0), RandomStream(9));
  const KeyPointTwin<StiffeningNonlinearity> stiffening(options_with(3, 1.0), RandomStream(9));
  const KeyPointTwin<KinkNonlinearity> kink(options_with(3, 1.0), RandomStream(9));
  for (const double departure :
       {quadratic_departure(contact, x, contact.assembly_set().optimum(x), RandomStream(3)),
        quadratic_departure(stiffening, x, stiffening.assembly_set().optimum(x), RandomStream(3)),
        quadratic_departure(kink, x, kink.assembly_set().optimum(x), RandomStream(3))}) {
    EXPECT_GT(departure, 0.05);
    EXPECT_LT(departure, 1.0);
  }
}

TEST(KeyPointTwin, ContactIsPiecewiseAffineInTheControl) {
  // Along a short segment where no contact opens or closes, the deviations are affine: the
  // midpoint's are the mean of the ends'. Over the whole box some contact changes state.
  const KeyPointTwin<ContactNonlinearity> twin(options_with(3, 1.0), RandomStream(12));
  const AssemblyId x{5, 5};
  const VectorX a = twin.assembly_set().optimum(x);
  const VectorX step = VectorX::Constant(3, 1e-4);
  const VectorX mid = twin.deviations(x, a);
  const VectorX ends = 0.5 * (twin.deviations(x, a - step) + twin.deviations(x, a + step));
  EXPECT_LT((mid - ends).lpNorm<Eigen::Infinity>(), 1e-12);
  double largest = 0.0;
  for (double t = -1.0; t <= 1.0; t += 0.25) {
    const VectorX u = VectorX::Constant(3, t);
    const VectorX left = twin.deviations(x, VectorX(u - 0.125 * VectorX::Ones(3)));
    const VectorX right = twin.deviations(x, VectorX(u + 0.125 * VectorX::Ones(3)));
    largest = std::max(largest, (twin.deviations(x, u) - 0.5 * (left + right)).norm());
  }
  EXPECT_GT(largest, 1e-6);
}

TEST(KeyPointTwin, RefusesBadOptionsAndArgumentsNamingThem) {
  EXPECT_THROW(KeyPointTwin<NoNonlinearity>(options_with(3, -1.0), RandomStream(1)),
               InvalidArgumentError);
  EXPECT_THROW(KeyPointTwin<ContactNonlinearity>(options_with(3, 1.5), RandomStream(1)),
               InvalidArgumentError);
  KeyPointTwinOptions few = options_with(3, 1.0);
  few.key_points = 3;
  try {
    const KeyPointTwin<NoNonlinearity> twin(few, RandomStream(1));
    FAIL() << "3 key points for 3 locators were accepted";
  } catch (const InvalidArgumentError& error) {
    EXPECT_NE(std::string(error.what()).find("key_points"), std::string::npos) << error.what();
  }
  const KeyPointTwin<NoNonlinearity> twin(options_with(3, 1.0), RandomStream(1));
  EXPECT_THROW((void)twin.quality({0, 0}, VectorX::Zero(2)), DimensionMismatchError);
  EXPECT_THROW((void)twin.quality({10, 0}, VectorX::Zero(3)), InvalidArgumentError);
}

}  // namespace
}  // namespace twincal::key_point_twin_test
