#include "twincal/controllers/controller_state_json.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "twincal/core/error.hpp"

namespace twincal {
namespace {

TEST(ControllerStateJson, AnAssemblyReadsBackIncludingAScannedOnesId) {
  for (const AssemblyId id : {AssemblyId{0, 0}, AssemblyId{9, 4}, AssemblyId{3, -1}}) {
    AssemblyId back{7, 7};
    json_state::read_assembly(json_state::assembly_to_json(id), "assembly", back);
    EXPECT_EQ(back, id);
  }
}

TEST(ControllerStateJson, RefusesAnAssemblyOutsideTheIdsAndLeavesTheTargetAlone) {
  for (const char* text : {"[-1, 0]", "[0, -2]", "[0]", "[0, 1, 2]", "[0.5, 1]", "{}"}) {
    AssemblyId target{7, 7};
    EXPECT_THROW(json_state::read_assembly(nlohmann::json::parse(text), "assembly", target),
                 InvalidArgumentError)
        << text;
    EXPECT_EQ(target, (AssemblyId{7, 7})) << text;
  }
}

}  // namespace
}  // namespace twincal
