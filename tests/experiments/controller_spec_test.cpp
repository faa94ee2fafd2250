#include "twincal/experiments/controller_spec.hpp"

#include <gtest/gtest.h>

#include "twincal/core/error.hpp"

namespace twincal {
namespace {

TEST(ControllerSpec, PaperListsBaselineDefaultElevenWControllersAndActive) {
  const std::vector<ControllerSpec> specs = ControllerSpec::paper();
  ASSERT_EQ(specs.size(), 14U);
  EXPECT_EQ(specs[0].label(), "baseline");
  EXPECT_EQ(specs[1].label(), "default");
  EXPECT_EQ(specs[2].label(), "w=0");
  EXPECT_EQ(specs[5].label(), "w=0.3");
  EXPECT_EQ(specs[12].label(), "w=1");
  EXPECT_EQ(specs[13].label(), "active");
}

TEST(ControllerSpec, LabelsParseBackToTheSameSpec) {
  for (const ControllerSpec& spec : ControllerSpec::paper()) {
    EXPECT_EQ(ControllerSpec::parse(spec.label()), spec) << spec.label();
  }
  EXPECT_EQ(ControllerSpec::parse("nominal"), ControllerSpec::nominal());
  EXPECT_EQ(ControllerSpec::parse("active"), ControllerSpec::active());
  EXPECT_EQ(ControllerSpec::active().label(), "active");
  EXPECT_EQ(ControllerSpec::parse("w=0.30").label(), "w=0.3");
  EXPECT_EQ(ControllerSpec::parse("per-component:w=1"), ControllerSpec::per_component(1.0));
  EXPECT_EQ(ControllerSpec::per_component(0.5).label(), "per-component:w=0.5");
}

TEST(ControllerSpec, RejectsUnknownNamesAndWOutsideTheUnitInterval) {
  EXPECT_THROW((void)ControllerSpec::parse("w=1.5"), InvalidArgumentError);
  EXPECT_THROW((void)ControllerSpec::parse("w=abc"), InvalidArgumentError);
  EXPECT_THROW((void)ControllerSpec::parse("optimal"), InvalidArgumentError);
  EXPECT_THROW((void)ControllerSpec::parse(" default"), InvalidArgumentError);
  EXPECT_THROW((void)ControllerSpec::parse("per-component:w=2"), InvalidArgumentError);
  EXPECT_THROW((void)ControllerSpec::parse("per-component"), InvalidArgumentError);
  EXPECT_THROW((void)ControllerSpec::parse("per-component:default"), InvalidArgumentError);
}

TEST(ControllerSpec, OnlyFilterBasedControllersEstimate) {
  EXPECT_FALSE(ControllerSpec::baseline().estimates());
  EXPECT_FALSE(ControllerSpec::nominal().estimates());
  EXPECT_TRUE(ControllerSpec::default_controller().estimates());
  EXPECT_TRUE(ControllerSpec::lookahead(0.5).estimates());
  EXPECT_TRUE(ControllerSpec::per_component(0.5).estimates());
  EXPECT_TRUE(ControllerSpec::active().estimates());
}

TEST(ControllerSpec, OnlyTheWControllersUseW) {
  EXPECT_TRUE(ControllerSpec::lookahead(0.5).uses_w());
  EXPECT_TRUE(ControllerSpec::per_component(0.5).uses_w());
  EXPECT_FALSE(ControllerSpec::default_controller().uses_w());
  EXPECT_FALSE(ControllerSpec::active().uses_w());
  EXPECT_FALSE(ControllerSpec::baseline().uses_w());
}

}  // namespace
}  // namespace twincal
