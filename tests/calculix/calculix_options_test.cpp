#include "twincal/calculix/calculix_options.hpp"

#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "twincal/calculix/calculix_error.hpp"

namespace twincal {
namespace {

using ::testing::HasSubstr;

TEST(CalculixOptions, DefaultsAreValid) { EXPECT_FALSE(CalculixOptions{}.validate()); }

TEST(CalculixOptions, EachRuleNamesItsFieldAndValue) {
  const auto problem = [](auto change) {
    CalculixOptions options;
    change(options);
    return options.validate().value_or("");
  };
  EXPECT_THAT(problem([](CalculixOptions& o) { o.executable.clear(); }),
              HasSubstr("executable: value is empty"));
  EXPECT_THAT(problem([](CalculixOptions& o) { o.refinement = 0; }),
              HasSubstr("refinement: value is 0; rule: must lie in [1, 16]"));
  EXPECT_THAT(problem([](CalculixOptions& o) { o.section.thickness = -1.0; }),
              HasSubstr("section.thickness"));
  EXPECT_THAT(problem([](CalculixOptions& o) { o.nominal_gap = -0.1; }),
              HasSubstr("nominal_gap: value is -0.1"));
  EXPECT_THAT(problem([](CalculixOptions& o) { o.gap_stiffness = 0.0; }),
              HasSubstr("gap_stiffness: value is 0"));
  EXPECT_THAT(problem([](CalculixOptions& o) { o.open_gap_force = -1.0; }),
              HasSubstr("open_gap_force: value is -1"));
  EXPECT_THAT(problem([](CalculixOptions& o) { o.geometric_nonlinearity = false; }),
              HasSubstr("CalculiX solves gap elements only in a nonlinear (NLGEOM) step"));
  EXPECT_THAT(problem([](CalculixOptions& o) { o.max_increments = 0; }),
              HasSubstr("max_increments: value is 0"));
  EXPECT_THAT(problem([](CalculixOptions& o) { o.max_iterations = 0; }),
              HasSubstr("max_iterations: value is 0"));
  EXPECT_THAT(problem([](CalculixOptions& o) { o.max_cutbacks = 0; }),
              HasSubstr("max_cutbacks: value is 0"));
  EXPECT_THAT(problem([](CalculixOptions& o) { o.locator_bound = 0.0; }),
              HasSubstr("locator_bound: value is 0"));
  EXPECT_THAT(problem([](CalculixOptions& o) { o.solver_threads = 0; }),
              HasSubstr("solver_threads: value is 0"));
  EXPECT_THAT(problem([](CalculixOptions& o) { o.timeout = std::chrono::milliseconds(0); }),
              HasSubstr("timeout: value is 0; rule: must be > 0 (ms)"));
  // Without contact, small displacements are allowed.
  CalculixOptions linear;
  linear.contact = false;
  linear.geometric_nonlinearity = false;
  EXPECT_FALSE(linear.validate());
}

TEST(CalculixError, FailureNames) {
  EXPECT_STREQ(to_string(CalculixFailure::no_convergence), "no_convergence");
  EXPECT_STREQ(to_string(CalculixFailure::missing_executable), "missing_executable");
  const CalculixError error(CalculixFailure::timeout, "message", "tail");
  EXPECT_EQ(error.failure(), CalculixFailure::timeout);
  EXPECT_EQ(error.log_tail(), "tail");
  EXPECT_EQ(error.argument(), "calculix");
}

}  // namespace
}  // namespace twincal
