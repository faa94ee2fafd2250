// The public conformance suites (models/testing) on a program's twin: a pool of
// tests/data/script_twin.py processes, which answers its d + 1 key points' deviations.
#include <chrono>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "twincal/external/external_twin_pool.hpp"
#include "twincal/models/testing/deviations_conformance.hpp"
#include "twincal/models/testing/twin_conformance.hpp"

namespace twincal::external_conformance_test {
namespace {

struct ScriptTwinPoolCase {
  using Twin = ExternalTwinPool;
  static Twin make() {
    ExternalTwinPoolOptions options;
    options.twin.command = {TWINCAL_TEST_DATA_DIR "/script_twin.py"};
    options.twin.locator_names = {"A", "B"};
    options.twin.lower_bounds = VectorX::Constant(2, -1.0);
    options.twin.upper_bounds = VectorX::Constant(2, 1.0);
    options.twin.key_points = 3;
    // Generous: these bound only failures, and the machine may be loaded or sanitized.
    options.twin.timeout = std::chrono::milliseconds{5000};
    options.twin.startup_grace = std::chrono::milliseconds{10000};
    options.workers = 2;
    return Twin(options);
  }
  static std::vector<nlohmann::json> assemblies() {
    return {{{"q0", 0.25}, {"a", {0.1, -0.2}}}, {{"q0", 0.01}, {"a", {-0.7, 0.4}}}};
  }
};

}  // namespace
}  // namespace twincal::external_conformance_test

namespace twincal::conformance {
INSTANTIATE_TYPED_TEST_SUITE_P(External, TwinConformance,
                               ::testing::Types<external_conformance_test::ScriptTwinPoolCase>);
INSTANTIATE_TYPED_TEST_SUITE_P(External, DeviationsConformance,
                               ::testing::Types<external_conformance_test::ScriptTwinPoolCase>);
}  // namespace twincal::conformance
