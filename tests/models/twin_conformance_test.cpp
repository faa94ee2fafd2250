// The twin conformance suite (models/testing/twin_conformance.hpp) for every twin of the module:
// the analytic twins, the key-point twin with each nonlinearity, a locator subset and evaluators.
// The sheet-metal FEM twins are instantiated in tests/sheet_metal/twin_conformance_test.cpp.
#include "twincal/models/testing/twin_conformance.hpp"
#include "twincal/models/testing/deviations_conformance.hpp"

#include <vector>

#include <gtest/gtest.h>

#include "twincal/core/random_stream.hpp"
#include "twincal/models/assembly_id.hpp"
#include "twincal/models/contact_nonlinearity.hpp"
#include "twincal/models/evaluator.hpp"
#include "twincal/models/key_point_twin.hpp"
#include "twincal/models/kink_nonlinearity.hpp"
#include "twincal/models/locator_subset.hpp"
#include "twincal/models/no_nonlinearity.hpp"
#include "twincal/models/parallel_execution.hpp"
#include "twincal/models/rms_quadratic_twin.hpp"
#include "twincal/models/rugged_twin.hpp"
#include "twincal/models/stiffening_nonlinearity.hpp"

namespace twincal::twin_conformance_test {
namespace {

// Corners and the middle of the 10 × 10 analytic assemblies.
std::vector<AssemblyId> analytic_assemblies() { return {{0, 0}, {3, 7}, {9, 9}}; }

const RmsQuadraticTwin& rms_quadratic_twin() {
  static const RmsQuadraticTwin twin = [] {
    RmsQuadraticTwinOptions options;
    options.assemblies.dimension = 5;
    return RmsQuadraticTwin::generate(options, RandomStream(31));
  }();
  return twin;
}

struct RmsQuadraticCase {
  using Twin = RmsQuadraticTwin;
  static Twin make() { return rms_quadratic_twin(); }
  static std::vector<AssemblyId> assemblies() { return analytic_assemblies(); }
};

struct RuggedCase {
  using Twin = RuggedTwin;
  static Twin make() {
    RuggedTwinOptions options;
    options.assemblies.dimension = 3;
    return {options, RandomStream(32)};
  }
  static std::vector<AssemblyId> assemblies() { return analytic_assemblies(); }
};

template <typename Nonlinearity>
struct KeyPointCase {
  using Twin = KeyPointTwin<Nonlinearity>;
  static Twin make() {
    KeyPointTwinOptions options;
    options.assemblies.dimension = 4;
    options.strength = 1.0;
    return {options, RandomStream(33)};
  }
  static std::vector<AssemblyId> assemblies() { return analytic_assemblies(); }
};

// Locators 4 and 1 of the 5, in that order: the subset refers to the full twin above.
struct LocatorSubsetCase {
  using Twin = LocatorSubset<RmsQuadraticTwin>;
  static Twin make() { return {rms_quadratic_twin(), {4, 1}}; }
  static std::vector<AssemblyId> assemblies() { return analytic_assemblies(); }
};

// The evaluator is a twin too: serially, and over a thread pool with its memo shared by the
// callers' threads (it refers to the twin, which outlives it).
struct SerialEvaluatorCase {
  using Twin = Evaluator<RmsQuadraticTwin>;
  static Twin make() { return Twin(rms_quadratic_twin()); }
  static std::vector<AssemblyId> assemblies() { return analytic_assemblies(); }
};

const KeyPointTwin<ContactNonlinearity>& contact_twin() {
  static const KeyPointTwin<ContactNonlinearity> twin = KeyPointCase<ContactNonlinearity>::make();
  return twin;
}

struct ParallelMemoizingEvaluatorCase {
  using Twin = Evaluator<KeyPointTwin<ContactNonlinearity>, ParallelExecution>;
  static Twin make() { return Twin(contact_twin(), ParallelExecution(3, 2), {.memoize = true}); }
  static std::vector<AssemblyId> assemblies() { return analytic_assemblies(); }
};

using Twins =
    ::testing::Types<RmsQuadraticCase, RuggedCase, KeyPointCase<NoNonlinearity>,
                     KeyPointCase<ContactNonlinearity>, KeyPointCase<StiffeningNonlinearity>,
                     KeyPointCase<KinkNonlinearity>, LocatorSubsetCase, SerialEvaluatorCase,
                     ParallelMemoizingEvaluatorCase>;

// The twins that answer their key points' deviations.
using TwinsWithDeviations =
    ::testing::Types<KeyPointCase<NoNonlinearity>, KeyPointCase<ContactNonlinearity>,
                     KeyPointCase<StiffeningNonlinearity>, KeyPointCase<KinkNonlinearity>>;

}  // namespace
}  // namespace twincal::twin_conformance_test

namespace twincal::conformance {
INSTANTIATE_TYPED_TEST_SUITE_P(Models, TwinConformance, twin_conformance_test::Twins);
INSTANTIATE_TYPED_TEST_SUITE_P(Models, DeviationsConformance,
                               twin_conformance_test::TwinsWithDeviations);
}  // namespace twincal::conformance
