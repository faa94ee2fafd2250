#include "twincal/models/quadratic_departure.hpp"

#include <cmath>

#include <gtest/gtest.h>

#include "twincal/core/error.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/models/rms_quadratic_twin.hpp"
#include "twincal/models/rugged_twin.hpp"

namespace twincal::quadratic_departure_test {
namespace {

// Q² = Σ e_k⁴ on a box [−1, 1]^d: far from a quadratic, with a departure known in closed form
// for d = 1 over [−½, ½]: x⁴ against its best quadratic on the uniform measure.
struct QuarticTwin {
  using Assembly = int;
  std::vector<std::string> names{"u1"};
  VectorX lower = VectorX::Constant(1, -1.0);
  VectorX upper = VectorX::Constant(1, 1.0);
  [[nodiscard]] Index control_dimension() const { return 1; }
  [[nodiscard]] const std::vector<std::string>& locator_names() const { return names; }
  [[nodiscard]] const VectorX& lower_bounds() const { return lower; }
  [[nodiscard]] const VectorX& upper_bounds() const { return upper; }
  [[nodiscard]] double quality(int /*x*/, const Eigen::Ref<const VectorX>& u) const {
    return u(0) * u(0);
  }
  void quality_batch(int x, const Eigen::Ref<const MatrixX>& u, Eigen::Ref<VectorX> out) const {
    for (Index j = 0; j < u.cols(); ++j) out(j) = quality(x, u.col(j));
  }
};

TEST(QuadraticDeparture, ZeroForAQuadraticTwin) {
  RmsQuadraticTwinOptions options;
  options.assemblies.dimension = 4;
  const RmsQuadraticTwin twin = RmsQuadraticTwin::generate(options, RandomStream(3));
  const VectorX center = VectorX::Constant(4, 0.2);
  EXPECT_LT(quadratic_departure(twin, AssemblyId{1, 1}, center, RandomStream(7)), 1e-9);
}

TEST(QuadraticDeparture, MatchesTheClosedFormForAQuartic) {
  // x ~ U(−½, ½): the best quadratic fit of x⁴ (x is uncorrelated with x² and x⁴ by symmetry)
  // leaves Var(x⁴ − P(x⁴ | 1, x²)) / Var(x⁴) = 1 − corr(x⁴, x²)², from the moments:
  // E x² = 1/12, E x⁴ = 1/80, E x⁶ = 1/448, E x⁸ = 1/2304.
  const double var4 = 1.0 / 2304 - std::pow(1.0 / 80, 2);
  const double var2 = 1.0 / 80 - std::pow(1.0 / 12, 2);
  const double cov = 1.0 / 448 - (1.0 / 80) * (1.0 / 12);
  const double expected = std::sqrt(1.0 - cov * cov / (var4 * var2));
  QuadraticDepartureOptions options;
  options.points_per_coefficient = 20000;
  const double departure =
      quadratic_departure(QuarticTwin{}, 0, VectorX::Zero(1), RandomStream(1), options);
  EXPECT_NEAR(departure, expected, 0.02 * expected);
}

TEST(QuadraticDeparture, SeesAKink) {
  RuggedTwinOptions options;
  options.ripple = 0.0;
  const RuggedTwin twin(options, RandomStream(2));
  const AssemblyId x{0, 0};
  EXPECT_GT(quadratic_departure(twin, x, twin.assembly_set().optimum(x), RandomStream(4)), 0.05);
}

TEST(QuadraticDeparture, RefusesBadArguments) {
  EXPECT_THROW((void)quadratic_departure(QuarticTwin{}, 0, VectorX::Zero(2), RandomStream(1)),
               DimensionMismatchError);
  QuadraticDepartureOptions options;
  options.half_width_fraction = 0.0;
  EXPECT_THROW(
      (void)quadratic_departure(QuarticTwin{}, 0, VectorX::Zero(1), RandomStream(1), options),
      InvalidArgumentError);
}

}  // namespace
}  // namespace twincal::quadratic_departure_test
