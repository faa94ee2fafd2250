#include "twincal/controllers/searched_optimum_twin.hpp"

#include <gtest/gtest.h>

#include "twincal/core/error.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/models/key_point_twin.hpp"
#include "twincal/models/no_nonlinearity.hpp"
#include "twincal/models/stiffening_nonlinearity.hpp"

namespace twincal::searched_optimum_twin_test {
namespace {

KeyPointTwinOptions options_with(Index d, double strength) {
  KeyPointTwinOptions options;
  options.assemblies.dimension = d;
  options.assemblies.upper_parts = 2;
  options.assemblies.lower_parts = 3;
  options.strength = strength;
  return options;
}

TEST(SearchedOptimumTwin, FindsTheKnownOptimumOfAQuadraticTwin) {
  KeyPointTwin<NoNonlinearity> twin(options_with(3, 0.0), RandomStream(4));
  const std::vector<AssemblyId> assemblies = twin.assemblies();
  const KeyPointTwin<NoNonlinearity> reference = twin;
  const SearchedOptimumTwin<KeyPointTwin<NoNonlinearity>> searched(std::move(twin), assemblies);
  static_assert(TwinWithOptimum<SearchedOptimumTwin<KeyPointTwin<NoNonlinearity>>>);
  for (const AssemblyId& x : assemblies) {
    const VectorX exact = reference.assembly_set().optimum(x);
    EXPECT_LT((searched.optimum(x) - exact).norm(), 1e-5);
    EXPECT_NEAR(searched.optimal_quality(x), std::sqrt(reference.assembly_set().q0(x)), 1e-9);
  }
  EXPECT_GT(searched.search_evaluations(), 0U);
}

TEST(SearchedOptimumTwin, NoControlNearbyBeatsTheSearchedOptimumOfANonlinearTwin) {
  KeyPointTwin<StiffeningNonlinearity> twin(options_with(3, 1.0), RandomStream(6));
  const std::vector<AssemblyId> assemblies = twin.assemblies();
  const SearchedOptimumTwin<KeyPointTwin<StiffeningNonlinearity>> searched(std::move(twin),
                                                                           assemblies);
  RandomStream draws(1);
  for (const AssemblyId& x : assemblies) {
    const VectorX u0 = searched.optimum(x);
    EXPECT_DOUBLE_EQ(searched.quality(x, u0), searched.optimal_quality(x));
    for (int trial = 0; trial < 50; ++trial) {
      VectorX u = u0;
      for (double& v : u) v += 0.02 * (2.0 * draws.uniform() - 1.0);
      u = u.cwiseMax(searched.lower_bounds()).cwiseMin(searched.upper_bounds());
      EXPECT_GE(searched.quality(x, u), searched.optimal_quality(x) - 1e-9);
    }
  }
}

TEST(SearchedOptimumTwin, RefusesAnUnknownAssemblyAndAnEmptyList) {
  KeyPointTwin<NoNonlinearity> twin(options_with(2, 0.0), RandomStream(1));
  EXPECT_THROW(SearchedOptimumTwin<KeyPointTwin<NoNonlinearity>>(twin, {}), InvalidArgumentError);
  const SearchedOptimumTwin<KeyPointTwin<NoNonlinearity>> searched(twin, {{0, 0}});
  EXPECT_THROW((void)searched.optimum({1, 1}), InvalidArgumentError);
}

}  // namespace
}  // namespace twincal::searched_optimum_twin_test
