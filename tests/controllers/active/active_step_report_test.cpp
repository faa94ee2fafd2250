// ActiveStepReport as JSON: every field written and read back exactly, NaN and ±∞ included; a
// missing or mistyped field refused by name.
#include "twincal/controllers/active/active_step_report.hpp"

#include <limits>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "twincal/core/error.hpp"

namespace twincal {
namespace {

ActiveStepReport filled_report() {
  return {.quadratic = true,
          .model_error = 0.125,
          .model_variance = 3e-9,
          .hessian_refitted = true,
          .probe_norm = 0.0421,
          .plant_regret = 1.5e-4,
          .horizon = 37.0,
          .process_variance = 2e-6,
          .normalized_innovation = std::numeric_limits<double>::infinity(),
          .normalized_residual = 0.375,
          .gated = true,
          .velocity_change = true,
          .change_ratio = 1.75,
          .misfit_scale = 57.5,
          .prediction_scale = 2.25,
          .fit_unit = 0.0625,
          .history = 25,
          .correction_wanted = true,
          .held_by_innovations = true,
          .held_by_surprises = true,
          .held_beyond_reach = true,
          .held_by_audit = true,
          .corrected = true,
          .audited = true};
}

// Read back, the report writes the same JSON (NaN as null): every field survived, since each
// field has its own key (the key count below) and a value none of the defaults has.
void expect_same(const ActiveStepReport& read, const ActiveStepReport& written) {
  EXPECT_EQ(active_step_report_to_json(read).dump(), active_step_report_to_json(written).dump());
}

TEST(ActiveStepReport, ReadsBackEveryFieldThroughJsonText) {
  const ActiveStepReport written = filled_report();
  const nlohmann::json json = nlohmann::json::parse(active_step_report_to_json(written).dump());
  EXPECT_EQ(json.size(), 24U) << "one key per field";
  EXPECT_EQ(json["normalized_innovation"], "inf");
  expect_same(read_active_step_report(json), written);
}

// A default report (no estimator has run) keeps its NaN readings as null.
TEST(ActiveStepReport, KeepsTheReadingsOfAnEstimatorThatDidNotRunAsNull) {
  const ActiveStepReport written;
  const nlohmann::json json = active_step_report_to_json(written);
  EXPECT_TRUE(json["change_ratio"].is_null());
  EXPECT_TRUE(json["misfit_scale"].is_null());
  EXPECT_TRUE(json["prediction_scale"].is_null());
  EXPECT_TRUE(json["fit_unit"].is_null());
  EXPECT_TRUE(json["normalized_residual"].is_null());
  expect_same(read_active_step_report(json), written);
}

TEST(ActiveStepReport, RefusesAMissingOrMistypedFieldByName) {
  nlohmann::json json = active_step_report_to_json(filled_report());
  json.erase("misfit_scale");
  EXPECT_THAT([&] { (void)read_active_step_report(json); },
              ::testing::ThrowsMessage<InvalidArgumentError>(
                  ::testing::HasSubstr("misfit_scale: field is missing")));
  json = active_step_report_to_json(filled_report());
  json["velocity_change"] = 1;
  EXPECT_THAT([&] { (void)read_active_step_report(json); },
              ::testing::ThrowsMessage<InvalidArgumentError>(
                  ::testing::HasSubstr("velocity_change: is 1; rule: must be true or false")));
  json = active_step_report_to_json(filled_report());
  json["change_ratio"] = "large";
  EXPECT_THAT([&] { (void)read_active_step_report(json); },
              ::testing::ThrowsMessage<InvalidArgumentError>(
                  ::testing::HasSubstr("change_ratio: is \"large\"; rule: must be a number")));
}

}  // namespace
}  // namespace twincal
