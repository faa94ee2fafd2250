#include "twincal/sheet_metal/contact_sheet_metal_twin.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "contact_test_layouts.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/models/quadratic_departure.hpp"
#include "twincal/sheet_metal/plate_mesh.hpp"
#include "twincal/sheet_metal/sheet_metal_process.hpp"

namespace twincal::contact_sheet_metal_twin_test {
namespace {

SheetMetalTwin small_linear(bool door_like) {
  return contact_test_layouts::small_lap_joint_twin(door_like, 17);
}

ContactSheetMetalTwin small_twin(bool door_like, double nominal_gap) {
  ContactSheetMetalTwinOptions options;
  options.nominal_gap = nominal_gap;
  return ContactSheetMetalTwin(small_linear(door_like), options);
}

// `count` controls: uniform in the box, every fourth one a corner.
MatrixX box_controls(const ContactSheetMetalTwin& twin, Index count, RandomStream& stream) {
  MatrixX controls(twin.control_dimension(), count);
  for (Index j = 0; j < count; ++j) {
    for (Index k = 0; k < controls.rows(); ++k) {
      const double unit = stream.uniform();
      const double value = j % 4 == 3 ? (unit < 0.5 ? -1.0 : 1.0) : 2.0 * unit - 1.0;
      controls(k, j) = value * twin.upper_bounds()(k);
    }
  }
  return controls;
}

class ContactTwinLayout : public ::testing::TestWithParam<bool> {};

TEST_P(ContactTwinLayout, HugeGapsGiveTheLinearTwin) {
  const ContactSheetMetalTwin twin = small_twin(GetParam(), 1e6);
  const SheetMetalTwin& linear = twin.linear();
  RandomStream stream(41);
  const MatrixX controls = box_controls(twin, 20, stream);
  for (const AssemblyId& x : twin.assemblies()) {
    for (Index j = 0; j < controls.cols(); ++j) {
      const SheetMetalContactState state = twin.contact_state(x, controls.col(j));
      EXPECT_EQ(state.force, VectorX::Zero(twin.pair_count()));
      EXPECT_EQ(state.summary.iterations, 0);
      const VectorX expected = linear.key_deviation(x, controls.col(j));
      EXPECT_LT((state.deviation - expected).cwiseAbs().maxCoeff(),
                1e-12 * (1.0 + expected.cwiseAbs().maxCoeff()));
      const double q = linear.quality(x, controls.col(j));
      EXPECT_NEAR(twin.quality(x, controls.col(j)), q, 1e-10 * q);
    }
  }
}

TEST_P(ContactTwinLayout, TheSolutionIsFeasibleAndComplementary) {
  // Nominal touching (gap 0): the parts' shapes press some flange nodes into each other.
  const ContactSheetMetalTwin twin = small_twin(GetParam(), 0.0);
  RandomStream stream(42);
  const MatrixX controls = box_controls(twin, 40, stream);
  Index fewest = twin.pair_count();
  Index most = 0;
  for (const AssemblyId& x : twin.assemblies()) {
    for (Index j = 0; j < controls.cols(); ++j) {
      const SheetMetalContactState state = twin.contact_state(x, controls.col(j));
      const VectorX unloaded = twin.unloaded_gap(x, controls.col(j));
      const double scale = unloaded.cwiseAbs().maxCoeff();
      EXPECT_GE(state.force.minCoeff(), 0.0);
      EXPECT_GE(state.gap.minCoeff(), -1e-9 * scale);  // no penetration
      for (Index k = 0; k < twin.pair_count(); ++k) {
        EXPECT_LE(std::abs(state.force(k) * state.gap(k)),
                  1e-9 * scale * (1.0 + state.force.maxCoeff()));
      }
      EXPECT_LE(state.summary.residual, 1e-9 * scale);
      EXPECT_EQ(state.summary.status, ContactSolverStatus::solved);
      // g = g⁰ + C f and y = y_lin + K f.
      const VectorX gap = unloaded + twin.compliance() * state.force;
      EXPECT_LT((state.gap - gap).cwiseAbs().maxCoeff(), 1e-12 * (1.0 + scale));
      const VectorX y =
          twin.linear().key_deviation(x, controls.col(j)) + twin.key_response() * state.force;
      EXPECT_LT((state.deviation - y).cwiseAbs().maxCoeff(), 1e-12);
      fewest = std::min(fewest, state.summary.closed);
      most = std::max(most, state.summary.closed);
    }
  }
  // Not vacuous: contacts close, and open again elsewhere in the box.
  EXPECT_GT(most, 0);
  EXPECT_LT(fewest, most);
}

TEST_P(ContactTwinLayout, TheFullFieldAgreesWithTheCondensedModel) {
  // The contact forces applied to the whole released assembly (an independent FEM solve): its
  // gaps at the pairs are the LCP's gaps (no penetration) and its key points the deviations.
  const ContactSheetMetalTwin twin = small_twin(GetParam(), 0.0);
  const SheetMetalProcess& process = twin.linear().process();
  RandomStream stream(43);
  const MatrixX controls = box_controls(twin, 12, stream);
  Index with_contact = 0;
  for (const AssemblyId& x : twin.assemblies()) {
    for (Index j = 0; j < controls.cols(); ++j) {
      const SheetMetalContactState state = twin.contact_state(x, controls.col(j));
      if (state.summary.closed == 0) continue;
      ++with_contact;
      const VectorX elastic = twin.released_state(x, controls.col(j));
      const VectorX& upper_free = twin.linear().upper_part(x.upper);
      const VectorX& lower_free = twin.linear().lower_part(x.lower);
      const auto total_w = [&](SheetMetalPart part, Index node) {
        const Index local = PlateMesh::dof(node, 0);
        const double free = part == SheetMetalPart::upper ? upper_free(local) : lower_free(local);
        return free + elastic(process.global_dof(part, local));
      };
      for (Index k = 0; k < twin.pair_count(); ++k) {
        const ContactPair& pair = twin.pairs()[static_cast<std::size_t>(k)];
        const double gap = twin.options().nominal_gap +
                           total_w(SheetMetalPart::upper, pair.upper_node) -
                           total_w(SheetMetalPart::lower, pair.lower_node);
        EXPECT_NEAR(gap, state.gap(k), 1e-9);
        EXPECT_GE(gap, -1e-9);
      }
      for (Index i = 0; i < process.key_point_count(); ++i) {
        const SheetMetalPart part = process.layout().key_points[static_cast<std::size_t>(i)].part;
        EXPECT_NEAR(total_w(part, process.key_nodes()[static_cast<std::size_t>(i)]),
                    state.deviation(i), 1e-9);
      }
    }
  }
  EXPECT_GT(with_contact, 0);
}

TEST_P(ContactTwinLayout, BatchEqualsSingleCalls) {
  const ContactSheetMetalTwin twin = small_twin(GetParam(), 0.0);
  RandomStream stream(44);
  const MatrixX controls = box_controls(twin, 30, stream);
  VectorX batch(controls.cols());
  for (const AssemblyId& x : twin.assemblies()) {
    twin.quality_batch(x, controls, batch);
    for (Index j = 0; j < controls.cols(); ++j) {
      EXPECT_EQ(batch(j), twin.quality(x, controls.col(j)));  // bit for bit
      const VectorX y = twin.key_deviation(x, controls.col(j));
      EXPECT_NEAR(batch(j), y.norm() / std::sqrt(static_cast<double>(y.size())), 1e-14);
    }
  }
}

TEST_P(ContactTwinLayout, ContactBendsQSquared) {
  const ContactSheetMetalTwin twin = small_twin(GetParam(), 0.0);
  RandomStream stream(45);
  const MatrixX controls = box_controls(twin, 40, stream);
  double largest_change = 0.0;
  double largest_departure = 0.0;
  for (const AssemblyId& x : twin.assemblies()) {
    for (Index j = 0; j < controls.cols(); ++j) {
      const double contact = twin.quality(x, controls.col(j));
      const double linear = twin.linear().quality(x, controls.col(j));
      EXPECT_GE(contact, 0.0);
      largest_change = std::max(largest_change, std::abs(contact - linear) / linear);
    }
    largest_departure = std::max(
        largest_departure, quadratic_departure(twin, x, twin.search_start(x), RandomStream(9)));
  }
  EXPECT_GT(largest_change, 1e-3);
  EXPECT_GT(largest_departure, 1e-3);
}

INSTANTIATE_TEST_SUITE_P(BodyAndDoorLike, ContactTwinLayout, ::testing::Bool());

TEST(ContactSheetMetalTwin, KeepsTheLinearTwinsInterface) {
  const ContactSheetMetalTwin twin = small_twin(false, 0.0);
  const SheetMetalTwin& linear = twin.linear();
  EXPECT_EQ(twin.control_dimension(), 6);
  EXPECT_EQ(twin.locator_names(), linear.locator_names());
  EXPECT_EQ(twin.lower_bounds(), linear.lower_bounds());
  EXPECT_EQ(twin.upper_bounds(), linear.upper_bounds());
  EXPECT_EQ(twin.assemblies(), linear.assemblies());
  EXPECT_EQ(twin.significant_locators(), linear.significant_locators());
  EXPECT_EQ(twin.search_start({1, 0}), linear.optimum({1, 0}));
  EXPECT_EQ(twin.pair_count(), 28);
  EXPECT_EQ(twin.compliance().rows(), 28);
  EXPECT_EQ(twin.key_response().rows(), 8);
  EXPECT_EQ(twin.gap_influence().cols(), 6);
  // Copies share the factorization and evaluate the same.
  const ContactSheetMetalTwin copy = twin;  // NOLINT(performance-unnecessary-copy-initialization)
  const VectorX u = VectorX::Constant(6, 0.5);
  EXPECT_EQ(copy.quality({1, 1}, u), twin.quality({1, 1}, u));
  EXPECT_EQ(copy.released_state({1, 1}, u), twin.released_state({1, 1}, u));
}

TEST(ContactSheetMetalTwin, RefusesBadInput) {
  ContactSheetMetalTwinOptions options;
  options.nominal_gap = -1.0;
  EXPECT_EQ(options.validate(),
            std::optional<std::string>("nominal_gap: value is -1; rule: must be finite and >= 0 "
                                       "(mm)"));
  options.nominal_gap = std::nan("");
  EXPECT_TRUE(options.validate().has_value());
  options.nominal_gap = 0.1;
  options.solver.tolerance = 2.0;
  EXPECT_EQ(options.validate(),
            std::optional<std::string>("solver.tolerance: value is 2; rule: must lie in (0, 1)"));
  try {
    (void)ContactSheetMetalTwin(small_linear(false), options);
    FAIL();
  } catch (const InvalidArgumentError& error) {
    EXPECT_EQ(error.argument(), "options");
  }

  const ContactSheetMetalTwin twin = small_twin(false, 0.0);
  const VectorX u = VectorX::Zero(6);
  try {
    (void)twin.quality({2, 0}, u);
    FAIL();
  } catch (const InvalidArgumentError& error) {
    EXPECT_EQ(std::string(error.what()),
              "assembly: value is (upper 2, lower 0); rule: upper must lie in [0, 2) and lower in "
              "[0, 2)");
  }
  EXPECT_THROW((void)twin.quality({0, 0}, VectorX::Zero(5)), DimensionMismatchError);
  VectorX nan_control = u;
  nan_control(3) = std::nan("");
  try {
    (void)twin.quality({0, 0}, nan_control);
    FAIL();
  } catch (const NonFiniteError& error) {
    EXPECT_EQ(std::string(error.what()),
              "control: entry 3 is nan; rule: every entry must be finite");
  }
  MatrixX controls = MatrixX::Zero(6, 3);
  VectorX out(2);
  EXPECT_THROW(twin.quality_batch({0, 0}, controls, out), DimensionMismatchError);
  VectorX out3(3);
  controls(2, 1) = std::nan("");
  EXPECT_THROW(twin.quality_batch({0, 0}, controls, out3), NonFiniteError);
  EXPECT_THROW((void)twin.unloaded_gap({0, 0}, VectorX::Zero(7)), DimensionMismatchError);
}

TEST(ContactSheetMetalTwin, TheCasesOpenAndCloseContactsInTheBox) {
  // The body and door cases with the default nominal gap: contacts close somewhere in the box
  // and not everywhere, and Q² departs from a quadratic (measured in docs/sheet_metal.md).
  for (const SheetMetalCase which : {SheetMetalCase::body, SheetMetalCase::door}) {
    const ContactSheetMetalTwin twin = ContactSheetMetalTwin::make(which, 2023);
    EXPECT_EQ(twin.pair_count(), which == SheetMetalCase::body ? 145 : 163);
    RandomStream stream(46);
    const MatrixX controls = box_controls(twin, 64, stream);
    Index fewest = twin.pair_count();
    Index most = 0;
    for (Index j = 0; j < controls.cols(); ++j) {
      const Index closed = twin.contact_state({0, 0}, controls.col(j)).summary.closed;
      fewest = std::min(fewest, closed);
      most = std::max(most, closed);
    }
    EXPECT_LT(fewest, most);
    EXPECT_LT(most, twin.pair_count() / 2);
    const double departure =
        quadratic_departure(twin, AssemblyId{0, 0}, twin.search_start({0, 0}), RandomStream(7));
    EXPECT_GT(departure, which == SheetMetalCase::body ? 1e-4 : 1e-2);
  }
}

}  // namespace
}  // namespace twincal::contact_sheet_metal_twin_test
