// QuadraticQualityMeasurement: the analytic measurement of the reference runs, its batch hook and
// its argument checks.
#include "twincal/filters/quadratic_quality_measurement.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "twincal/filters/measurement_model.hpp"

namespace twincal {
namespace {

using ::testing::HasSubstr;

static_assert(BatchMeasurementModel<QuadraticQualityMeasurement<3>>);
static_assert(BatchMeasurementModel<QuadraticQualityMeasurement<Dynamic>>);

template <typename Size>
class QuadraticQualityMeasurementTest : public ::testing::Test {};
using Dimensions =
    ::testing::Types<std::integral_constant<int, 2>, std::integral_constant<int, Dynamic>>;
TYPED_TEST_SUITE(QuadraticQualityMeasurementTest, Dimensions);

TYPED_TEST(QuadraticQualityMeasurementTest, IsTheRootOfTheOffsetQuadraticForm) {
  constexpr int N = TypeParam::value;
  SquareMatrix<N> h(2, 2);
  h << 2.0, 0.5, 0.5, 1.0;
  const QuadraticQualityMeasurement<N> model(h, 0.04, 1e-4);
  Vector<N> a(2);
  a << 0.1, -0.2;
  Vector<N> u(2);
  u << 0.4, 0.3;
  Vector<N> state(2);
  state << 0.1, 0.2;
  // e = u − δu − a = (0.2, 0.3); eᵀHe = 2·0.04 + 2·0.5·0.06 + 0.09 = 0.23.
  EXPECT_NEAR(model.measure(state, {a, u}), std::sqrt(0.04 + 0.23), 1e-15);
  EXPECT_EQ(model.noise_variance(), 1e-4);

  Matrix<N, 4> states(2, 4);
  states << 0.1, 0.0, -0.3, 1.0, 0.2, 0.0, 0.4, -1.0;
  Vector<4> batch;
  evaluate_measurements(model, states, {a, u}, batch);
  for (Index i = 0; i < 4; ++i) {
    const Vector<N> column = states.col(i);
    EXPECT_EQ(batch(i), model.measure(column, {a, u})) << "point " << i;
  }
}

TEST(QuadraticQualityMeasurement, NamesWhatIsWrong) {
  Eigen::Matrix2d indefinite;
  indefinite << 1.0, 0.0, 0.0, -1.0;
  EXPECT_THAT([&] { (void)QuadraticQualityMeasurement<2>(indefinite, 0.04, 1e-4); },
              ::testing::ThrowsMessage<NotPositiveDefiniteError>(
                  HasSubstr("weight: smallest eigenvalue is -1")));
  EXPECT_THAT([] { (void)QuadraticQualityMeasurement<2>(Eigen::Matrix2d::Identity(), -1.0, 1e-4); },
              ::testing::ThrowsMessage<InvalidArgumentError>(
                  HasSubstr("offset: value is -1; rule: must be >= 0")));
  EXPECT_THAT([] { (void)QuadraticQualityMeasurement<2>(Eigen::Matrix2d::Identity(), 0.0, 0.0); },
              ::testing::ThrowsMessage<InvalidArgumentError>(
                  HasSubstr("noise_variance: value is 0; rule: must be > 0")));
  const QuadraticQualityMeasurement<Dynamic> model(MatrixX::Identity(3, 3), 0.0, 1.0);
  EXPECT_THAT(
      [&] {
        (void)model.measure(VectorX::Zero(3), {VectorX::Zero(2), VectorX::Zero(3)});
      },
      ::testing::ThrowsMessage<DimensionMismatchError>(
          HasSubstr("inputs.assembly: size is 2; rule: must equal 3")));
  VectorX out(2);
  EXPECT_THAT(
      [&] {
        model.measure_batch(MatrixX::Zero(3, 3), {VectorX::Zero(3), VectorX::Zero(3)}, out);
      },
      ::testing::ThrowsMessage<DimensionMismatchError>(
          HasSubstr("out: size is 2; rule: must equal 3")));
}

}  // namespace
}  // namespace twincal
