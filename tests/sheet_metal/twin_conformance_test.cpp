// The twin conformance suite (models/testing/twin_conformance.hpp) for the sheet-metal FEM
// twins: the linear and contact twins of the paper's 'body' case, and those of the small lap
// joints (body-like and door-like releases), the contact ones with touching flanges so that
// contacts open and close inside the box.
#include "twincal/models/testing/twin_conformance.hpp"
#include "twincal/models/testing/deviations_conformance.hpp"

#include <vector>

#include <gtest/gtest.h>

#include "contact_test_layouts.hpp"
#include "twincal/models/assembly_id.hpp"
#include "twincal/sheet_metal/contact_sheet_metal_twin.hpp"
#include "twincal/sheet_metal/sheet_metal_twin.hpp"

namespace twincal::sheet_metal_twin_conformance_test {
namespace {

SheetMetalTwin small_linear_twin(bool door_like) {
  return contact_test_layouts::small_lap_joint_twin(door_like, 23);
}

std::vector<AssemblyId> small_assemblies() { return {{0, 0}, {0, 1}, {1, 0}, {1, 1}}; }

struct BodyCase {
  using Twin = SheetMetalTwin;
  static Twin make() { return SheetMetalTwin::body(); }
  static std::vector<AssemblyId> assemblies() { return {{0, 0}, {3, 7}, {9, 9}}; }
};

struct ContactBodyCase {
  using Twin = ContactSheetMetalTwin;
  static Twin make() { return ContactSheetMetalTwin::body(); }
  static std::vector<AssemblyId> assemblies() { return {{0, 0}, {3, 7}, {9, 9}}; }
};

template <bool DoorLike>
struct SmallLinearCase {
  using Twin = SheetMetalTwin;
  static Twin make() { return small_linear_twin(DoorLike); }
  static std::vector<AssemblyId> assemblies() { return small_assemblies(); }
};

template <bool DoorLike>
struct SmallContactCase {
  using Twin = ContactSheetMetalTwin;
  static Twin make() {
    ContactSheetMetalTwinOptions options;
    options.nominal_gap = 0.0;
    return Twin(small_linear_twin(DoorLike), options);
  }
  static std::vector<AssemblyId> assemblies() { return small_assemblies(); }
};

using Twins =
    ::testing::Types<BodyCase, ContactBodyCase, SmallLinearCase<false>, SmallLinearCase<true>,
                     SmallContactCase<false>, SmallContactCase<true>>;

}  // namespace
}  // namespace twincal::sheet_metal_twin_conformance_test

namespace twincal::conformance {
INSTANTIATE_TYPED_TEST_SUITE_P(SheetMetal, TwinConformance,
                               sheet_metal_twin_conformance_test::Twins);
INSTANTIATE_TYPED_TEST_SUITE_P(SheetMetal, DeviationsConformance,
                               sheet_metal_twin_conformance_test::Twins);
}  // namespace twincal::conformance
