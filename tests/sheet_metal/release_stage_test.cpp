#include "twincal/sheet_metal/release_stage.hpp"

#include <gtest/gtest.h>

#include "contact_test_layouts.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/sheet_metal/plate_mesh.hpp"

namespace twincal::release_stage_test {
namespace {

class ReleaseStageLayout : public ::testing::TestWithParam<bool> {};

TEST_P(ReleaseStageLayout, ReleasedStateEqualsTheProcess) {
  // The stage refactorizes the process's release constraints: same set, same order, same state.
  const SheetMetalProcess process(contact_test_layouts::small_lap_joint(GetParam()),
                                  PlateSection{});
  const ReleaseStage stage(process);
  RandomStream stream(31);
  for (int trial = 0; trial < 3; ++trial) {
    VectorX upper(process.dof_count(SheetMetalPart::upper));
    VectorX lower(process.dof_count(SheetMetalPart::lower));
    VectorX control(process.control_dimension());
    stream.fill_normal(upper);
    stream.fill_normal(lower);
    stream.fill_normal(control);
    const VectorX expected = process.released_state(upper, lower, control);
    const VectorX found = stage.released_state(process, upper, lower, control);
    EXPECT_LT((found - expected).cwiseAbs().maxCoeff(), 1e-10 * expected.cwiseAbs().maxCoeff());
  }
}

TEST_P(ReleaseStageLayout, PairLoadResponsesAreReciprocalAndKeepTheConstraints) {
  const SheetMetalProcess process(contact_test_layouts::small_lap_joint(GetParam()),
                                  PlateSection{});
  const ReleaseStage stage(process);
  // Unit pair loads at two flange points (not welds): (40, 120) and (320, 200).
  const auto pair_load = [&](double x, double y) {
    VectorX load = VectorX::Zero(stage.dof_count());
    const Index u = process.model(SheetMetalPart::upper).mesh().node_at(x, y, "upper");
    const Index l = process.model(SheetMetalPart::lower).mesh().node_at(x, y, "lower");
    load(process.global_dof(SheetMetalPart::upper, PlateMesh::dof(u, 0))) = 1.0;
    load(process.global_dof(SheetMetalPart::lower, PlateMesh::dof(l, 0))) = -1.0;
    return load;
  };
  const VectorX a = pair_load(40.0, 120.0);
  const VectorX b = pair_load(320.0, 200.0);
  const VectorX ra = stage.response(a);
  const VectorX rb = stage.response(b);
  // Maxwell–Betti: the work of load a on b's displacement equals b's on a's.
  EXPECT_NEAR(a.dot(rb), b.dot(ra), 1e-10 * std::abs(a.dot(ra)));
  EXPECT_GT(a.dot(ra), 0.0);  // a pair force opens its own gap
  // Welds keep their relative displacement (zero change), supports stay.
  const std::vector<Index>& upper_welds = process.weld_nodes(SheetMetalPart::upper);
  const std::vector<Index>& lower_welds = process.weld_nodes(SheetMetalPart::lower);
  for (std::size_t j = 0; j < upper_welds.size(); ++j) {
    const double relative =
        ra(process.global_dof(SheetMetalPart::upper, PlateMesh::dof(upper_welds[j], 0))) -
        ra(process.global_dof(SheetMetalPart::lower, PlateMesh::dof(lower_welds[j], 0)));
    EXPECT_NEAR(relative, 0.0, 1e-12);
  }
  for (Index dof = 0; dof < stage.dof_count(); ++dof) {
    if (stage.prescribed(dof)) EXPECT_EQ(ra(dof), 0.0) << "dof " << dof;
  }
}

INSTANTIATE_TEST_SUITE_P(BodyAndDoorLike, ReleaseStageLayout, ::testing::Bool());

TEST(ReleaseStage, KnowsItsPrescribedDofsAndRefusesBadInput) {
  const SheetMetalProcess process(contact_test_layouts::small_lap_joint(true), PlateSection{});
  const ReleaseStage stage(process);
  Index prescribed = 0;
  for (Index dof = 0; dof < stage.dof_count(); ++dof) prescribed += stage.prescribed(dof) ? 1 : 0;
  EXPECT_EQ(prescribed, 6);  // the six frame pins
  const Index pin =
      process.global_dof(SheetMetalPart::lower, PlateMesh::dof(process.support_nodes()[0], 0));
  EXPECT_TRUE(stage.prescribed(pin));
  EXPECT_THROW((void)stage.prescribed(-1), InvalidArgumentError);
  EXPECT_THROW((void)stage.prescribed(stage.dof_count()), InvalidArgumentError);
  EXPECT_THROW((void)stage.response(VectorX::Zero(3)), DimensionMismatchError);
}

}  // namespace
}  // namespace twincal::release_stage_test
