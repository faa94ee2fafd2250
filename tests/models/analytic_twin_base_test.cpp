#include "twincal/models/analytic_twin_base.hpp"

#include <optional>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "twincal/core/error.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/models/analytic_assembly_set.hpp"

namespace twincal {
namespace {

struct PlumbingOptions {
  AnalyticAssemblyOptions assemblies;
  double extra = 1.0;

  [[nodiscard]] std::optional<std::string> validate() const {
    return first_problem(
        {rule::nested("assemblies", assemblies), rule::positive_finite("extra", extra)});
  }
};

/// The plumbing alone: a twin without a Q.
class PlumbingOnly : public AnalyticTwinBase {
 public:
  PlumbingOnly(const PlumbingOptions& options, const RandomStream& stream)
      : AnalyticTwinBase(draw_assemblies(options, stream)) {}
};

TEST(AnalyticTwinBase, AnswersTheTwinMembersFromItsAssemblies) {
  PlumbingOptions options;
  options.assemblies.dimension = 2;
  options.assemblies.locator_names = {"A", "B"};
  const PlumbingOnly twin(options, RandomStream(4));
  EXPECT_EQ(twin.control_dimension(), 2);
  EXPECT_THAT(twin.locator_names(), ::testing::ElementsAre("A", "B"));
  EXPECT_EQ(twin.lower_bounds(), VectorX::Constant(2, -1.0));
  EXPECT_EQ(twin.upper_bounds(), VectorX::Constant(2, 1.0));
  EXPECT_EQ(twin.assemblies().size(), 100U);
  EXPECT_EQ(&twin.assembly_set().locator_names(), &twin.locator_names());
}

TEST(AnalyticTwinBase, DrawsTheAssembliesFromTheirSubstream) {
  PlumbingOptions options;
  const RandomStream stream(8);
  const PlumbingOnly twin(options, stream);
  const AnalyticAssemblySet expected(options.assemblies, stream.substream("assemblies"));
  for (const AssemblyId& x : expected.assemblies()) {
    EXPECT_EQ(twin.assembly_set().q0(x), expected.q0(x));
    EXPECT_EQ(VectorX(twin.assembly_set().optimum(x)), VectorX(expected.optimum(x)));
  }
}

TEST(AnalyticTwinBase, ChecksTheTwinsOptionsFirst) {
  PlumbingOptions options;
  options.extra = -1.0;
  EXPECT_THAT([&] { (void)PlumbingOnly(options, RandomStream(1)); },
              ::testing::ThrowsMessage<InvalidArgumentError>(
                  ::testing::HasSubstr("options: extra: value is -1")));
}

}  // namespace
}  // namespace twincal
