#include "twincal/sheet_metal/contact_solver_error.hpp"

#include <string>

#include <gtest/gtest.h>

namespace twincal::contact_solver_error_test {
namespace {

TEST(ContactSolverError, NamesItsStatuses) {
  EXPECT_EQ(to_string(ContactSolverStatus::solved), "solved");
  EXPECT_EQ(to_string(ContactSolverStatus::iteration_limit), "iteration_limit");
  EXPECT_EQ(to_string(ContactSolverStatus::singular), "singular");
}

TEST(ContactSolverError, IsATwincalErrorCarryingTheSummary) {
  ContactSolverSummary summary;
  summary.status = ContactSolverStatus::iteration_limit;
  summary.iterations = 7;
  summary.closed = 3;
  summary.residual = 0.25;
  try {
    throw ContactSolverError("contact", "contact: stopped; rule: must solve", summary);
  } catch (const Error& error) {
    EXPECT_EQ(error.argument(), "contact");
    EXPECT_EQ(std::string(error.what()), "contact: stopped; rule: must solve");
    const auto* typed = dynamic_cast<const ContactSolverError*>(&error);
    ASSERT_NE(typed, nullptr);
    EXPECT_EQ(typed->summary().status, ContactSolverStatus::iteration_limit);
    EXPECT_EQ(typed->summary().iterations, 7);
    EXPECT_EQ(typed->summary().closed, 3);
    EXPECT_EQ(typed->summary().residual, 0.25);
  }
}

}  // namespace
}  // namespace twincal::contact_solver_error_test
