#include "twincal/calculix/calculix_model.hpp"

#include <sstream>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "twincal/calculix/calculix_error.hpp"
#include "twincal/core/error.hpp"

namespace twincal {
namespace {

using ::testing::HasSubstr;

Index count(const std::string& text, const std::string& what) {
  Index n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) {
    ++n;
  }
  return n;
}

CalculixParts flat_parts(const CalculixModel& model) {
  return {VectorX::Zero(model.mesh(SheetMetalPart::upper).node_count()),
          VectorX::Zero(model.mesh(SheetMetalPart::lower).node_count())};
}

TEST(CalculixModel, DeckHoldsTheMeshTheProcessAndTheContacts) {
  const CalculixModel model(SheetMetalLayout::lap_joint(), CalculixOptions{});
  EXPECT_EQ(model.control_dimension(), 6);
  EXPECT_EQ(model.key_point_count(), 8);
  EXPECT_EQ(model.contact_pairs().size(), 28U);  // 3 rows × 11 − 5 welds
  EXPECT_EQ(model.deck_node_count(), 2 * (66 + 66) + 5);
  const MatrixX controls = MatrixX::Constant(6, 3, 0.25);
  const std::string deck = model.deck(flat_parts(model), controls);
  EXPECT_EQ(count(deck, "*ELEMENT, TYPE=C3D8I"), 2);  // one set per sheet
  EXPECT_EQ(count(deck, "*ELEMENT, TYPE=GAPUNI"), 28);
  EXPECT_EQ(count(deck, "*GAP, ELSET="), 28);
  EXPECT_EQ(count(deck, "\n3\n"), 2 * 5);  // two equations per weld, three terms each
  EXPECT_EQ(count(deck, "*STEP, NLGEOM"), 2 * 3);
  EXPECT_EQ(count(deck, "*BOUNDARY, OP=NEW"), 2 * 3);
  EXPECT_EQ(count(deck, "*NODE PRINT, NSET=KEYS"), 3);
  EXPECT_EQ(count(deck, "*CONTROLS, PARAMETERS=TIME INCREMENTATION\n4, 8, 9, 200, 10, 4, , 20\n"),
            2 * 3);
}

TEST(CalculixModel, LinearDeckHasNoGapsAndNoNlgeom) {
  CalculixOptions options;
  options.contact = false;
  options.geometric_nonlinearity = false;
  const CalculixModel model(SheetMetalLayout::lap_joint(), options);
  const std::string deck = model.deck(flat_parts(model), MatrixX::Zero(6, 1));
  EXPECT_EQ(count(deck, "GAPUNI"), 0);
  EXPECT_EQ(count(deck, "*STEP, NLGEOM"), 0);
  EXPECT_EQ(count(deck, "*STEP\n*STATIC\n"), 2);
}

TEST(CalculixModel, RefinementKeepsEveryPointOnANode) {
  CalculixOptions options;
  options.refinement = 2;
  const CalculixModel model(SheetMetalLayout::lap_joint(), options);
  EXPECT_DOUBLE_EQ(model.layout().element_size, 20.0);
  EXPECT_EQ(model.mesh(SheetMetalPart::upper).node_count(), 21 * 11);
  EXPECT_EQ(model.contact_pairs().size(), 5U * 21U - 5U);
}

TEST(CalculixModel, ClearancesAndLocatorDisplacementsFollowTheParts) {
  CalculixOptions options;
  options.nominal_gap = 0.5;
  const CalculixModel model(SheetMetalLayout::lap_joint(), options);
  CalculixParts parts = flat_parts(model);
  parts.upper.setConstant(0.125);  // a part lifted by 0.125 mm: every clearance grows by it
  const std::string deck = model.deck(parts, MatrixX::Zero(6, 1));
  EXPECT_EQ(count(deck, "\n0.625, 0., 0., 1., , 10000, 1e-08\n"), 28);
  // The upper locators hold total deviation 0: e_z = 0 − 0.125 on both faces of each; the guns
  // close the welds' gap f_L − f_U = −0.125. Both in each of the two steps.
  EXPECT_EQ(count(deck, ", 3, 3, -0.125\n"), 2 * (3 * 2 + 5));
}

// CalculiX reads at most 20 characters per number: every field of the deck fits, whatever the
// values (a weld gap of 1.3877787807814457e-17 mm once made a deck CalculiX refused).
TEST(CalculixModel, EveryNumberFitsCalculixFields) {
  const CalculixModel model(SheetMetalLayout::lap_joint(), CalculixOptions{});
  CalculixParts parts = flat_parts(model);
  for (Index i = 0; i < parts.upper.size(); ++i) {
    parts.upper(i) = -1.0 / 3.0 * 1e-17 * static_cast<double>(i + 1);
    parts.lower(i) = 0.123456789012345678 * static_cast<double>(i % 7) - 1e-300;
  }
  const std::string deck = model.deck(parts, MatrixX::Constant(6, 2, -2.0 / 3.0));
  std::istringstream lines(deck);
  std::string line;
  Index numbers = 0;
  while (std::getline(lines, line)) {
    if (line.empty() || line.front() == '*') continue;  // keywords and comments
    std::istringstream fields(line);
    std::string field;
    while (std::getline(fields, field, ',')) {
      EXPECT_LE(field.size(), 21U) << field;  // a blank after the comma, then <= 20
      ++numbers;
    }
  }
  EXPECT_GT(numbers, 1000);
}

TEST(CalculixModel, RefusesWhatItCannotModelWithNamedRules) {
  SheetMetalLayout door_like = SheetMetalLayout::lap_joint();
  door_like.weld_tie = WeldTie::translation_and_rotation;
  try {
    const CalculixModel model(door_like, CalculixOptions{});
    FAIL() << "accepted rotation-locking welds";
  } catch (const InvalidArgumentError& error) {
    EXPECT_THAT(error.what(), HasSubstr("layout.weld_tie: value is translation_and_rotation"));
  }
  CalculixOptions bad;
  bad.refinement = 0;
  EXPECT_THROW(CalculixModel(SheetMetalLayout::lap_joint(), bad), InvalidArgumentError);
  SheetMetalLayout one_locator = SheetMetalLayout::lap_joint();
  one_locator.locators.erase(one_locator.locators.begin(), one_locator.locators.begin() + 2);
  EXPECT_THROW(CalculixModel(one_locator, CalculixOptions{}), InvalidArgumentError);
}

TEST(CalculixModel, RefusesBadPartsAndControls) {
  const CalculixModel model(SheetMetalLayout::lap_joint(), CalculixOptions{});
  CalculixParts parts = flat_parts(model);
  EXPECT_THROW((void)model.deck(parts, MatrixX::Zero(5, 1)), DimensionMismatchError);
  EXPECT_THROW((void)model.deck(parts, MatrixX::Zero(6, 0)), InvalidArgumentError);
  MatrixX nan_control = MatrixX::Zero(6, 2);
  nan_control(3, 1) = std::nan("");
  try {
    (void)model.deck(parts, nan_control);
    FAIL() << "accepted NaN";
  } catch (const NonFiniteError& error) {
    EXPECT_THAT(error.what(), HasSubstr("controls: entry (3, 1) is nan"));
  }
  parts.lower.resize(3);
  EXPECT_THROW((void)model.deck(parts, MatrixX::Zero(6, 1)), DimensionMismatchError);
  parts = flat_parts(model);
  parts.upper(4) = std::numeric_limits<double>::infinity();
  EXPECT_THROW(model.require_parts(parts), NonFiniteError);
}

TEST(CalculixModel, KeyDeviationsAreTheFreeShapePlusTheMeanFaceDisplacement) {
  const CalculixModel model(SheetMetalLayout::lap_joint(), CalculixOptions{});
  const CalculixParts parts = flat_parts(model);
  // A print that moves every key-point node by 0.3 mm on flat parts: y = 0.3 everywhere.
  NodePrint print;
  print.time = 2.0;
  for (Index node = 1; node <= model.deck_node_count(); ++node) {
    print.nodes.push_back(node);
    print.displacements.emplace_back(0.0, 0.0, 0.3);
  }
  EXPECT_TRUE(model.key_deviations(parts, print).isApproxToConstant(0.3, 1e-15));
  print.nodes.resize(3);
  print.displacements.resize(3);
  EXPECT_THROW((void)model.key_deviations(parts, print), CalculixError);
}

}  // namespace
}  // namespace twincal
