#include "twincal/experiments/active_options_json.hpp"

#include <functional>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "twincal/core/error.hpp"
#include "twincal/experiments/experiment_config.hpp"
#include "twincal/experiments/sweep.hpp"

namespace twincal {
namespace {

using nlohmann::json;

TEST(ActiveOverrides, OfTheDefaultsIsAnEmptyObject) {
  EXPECT_EQ(active_overrides(ActiveOptions{}), json::object());
}

TEST(ActiveOverrides, RoundTripsEveryKindOfSettingAndBothSections) {
  ActiveOptions options;
  options.regret_probe = 0.3;                        // double
  options.audit_period = 7;                          // Index
  options.fit_at_audited_arm = false;                // bool
  options.trajectory.max_iterations = 9;             // int
  options.trajectory.velocity_fraction = 0.1 / 3.0;  // not a short decimal
  options.surrogate.hessian_refresh = 4;
  const json written = active_overrides(options);
  EXPECT_EQ(written, json::parse(R"({"regret_probe": 0.3, "audit_period": 7,
      "fit_at_audited_arm": false, "trajectory": {"max_iterations": 9,
      "velocity_fraction": 0.03333333333333333}, "surrogate": {"hessian_refresh": 4}})"));
  ActiveOptions read;
  apply_active_overrides(json::parse(written.dump()), read);
  EXPECT_EQ(active_overrides(read), written);
  EXPECT_EQ(read.trajectory.velocity_fraction, options.trajectory.velocity_fraction);
}

// Every setting by its member's name: a key the table misspells, or a member it misses, fails
// here.
TEST(ApplyActiveOverrides, SetsEverySettingByItsMembersName) {
  struct Case {
    const char* path;
    json value;
    std::function<bool(const ActiveOptions&)> applied;
  };
  const std::vector<Case> cases{
      {"process_variance", 2e-4, [](auto& o) { return o.process_variance == 2e-4; }},
      {"min_process_variance", 2e-8, [](auto& o) { return o.min_process_variance == 2e-8; }},
      {"max_process_variance", 2e-2, [](auto& o) { return o.max_process_variance == 2e-2; }},
      {"adaptation_rate", 0.2, [](auto& o) { return o.adaptation_rate == 0.2; }},
      {"max_horizon", 50.0, [](auto& o) { return o.max_horizon == 50.0; }},
      {"max_probe_fraction", 0.2, [](auto& o) { return o.max_probe_fraction == 0.2; }},
      {"max_offset_fraction", 0.4, [](auto& o) { return o.max_offset_fraction == 0.4; }},
      {"clamp_beyond_reach", true, [](auto& o) { return o.clamp_beyond_reach; }},
      {"correction_step_fraction", 0.05,
       [](auto& o) { return o.correction_step_fraction == 0.05; }},
      {"surprise_step_fraction", 0.1, [](auto& o) { return o.surprise_step_fraction == 0.1; }},
      {"hold_after_surprises", 3, [](auto& o) { return o.hold_after_surprises == 3; }},
      {"trial_innovations", 3, [](auto& o) { return o.trial_innovations == 3; }},
      {"audit_after_failed_trial", false, [](auto& o) { return !o.audit_after_failed_trial; }},
      {"innovation_gate", 4.0, [](auto& o) { return o.innovation_gate == 4.0; }},
      {"covariance_floor", 1e-11, [](auto& o) { return o.covariance_floor == 1e-11; }},
      {"covariance_ceiling_fraction", 0.9,
       [](auto& o) { return o.covariance_ceiling_fraction == 0.9; }},
      {"quadratic_retry", 24, [](auto& o) { return o.quadratic_retry == 24; }},
      {"weigh_model_error", false, [](auto& o) { return !o.weigh_model_error; }},
      {"relinearization_budget", 1.5, [](auto& o) { return o.relinearization_budget == 1.5; }},
      {"relinearization_reach", 0.6, [](auto& o) { return o.relinearization_reach == 0.6; }},
      {"regret_probe", 0.15, [](auto& o) { return o.regret_probe == 0.15; }},
      {"regret_window", 6, [](auto& o) { return o.regret_window == 6; }},
      {"erring_probe_gain", 1.0, [](auto& o) { return o.erring_probe_gain == 1.0; }},
      {"audit_period", 11, [](auto& o) { return o.audit_period == 11; }},
      {"audit_window", 12, [](auto& o) { return o.audit_window == 12; }},
      {"audit_misfit", 5.0, [](auto& o) { return o.audit_misfit == 5.0; }},
      {"fit_at_audited_arm", false, [](auto& o) { return !o.fit_at_audited_arm; }},
      {"change_test_after_refit", false, [](auto& o) { return !o.change_test_after_refit; }},
      {"trajectory.initial_position_fraction", 0.2,
       [](auto& o) { return o.trajectory.initial_position_fraction == 0.2; }},
      {"trajectory.position_fraction", 0.6,
       [](auto& o) { return o.trajectory.position_fraction == 0.6; }},
      {"trajectory.velocity_fraction", 0.02,
       [](auto& o) { return o.trajectory.velocity_fraction == 0.02; }},
      {"trajectory.change_gate", 2.5, [](auto& o) { return o.trajectory.change_gate == 2.5; }},
      {"trajectory.change_window", 3, [](auto& o) { return o.trajectory.change_window == 3; }},
      {"trajectory.innovation_window", 0,
       [](auto& o) { return o.trajectory.innovation_window == 0; }},
      {"trajectory.misfit_window", 20, [](auto& o) { return o.trajectory.misfit_window == 20; }},
      {"trajectory.max_misfit_scale", 25.0,
       [](auto& o) { return o.trajectory.max_misfit_scale == 25.0; }},
      {"trajectory.max_position_fraction", 0.25,
       [](auto& o) { return o.trajectory.max_position_fraction == 0.25; }},
      {"trajectory.min_gate_unit", 0.1, [](auto& o) { return o.trajectory.min_gate_unit == 0.1; }},
      {"trajectory.min_erring_gate_unit", 0.1,
       [](auto& o) { return o.trajectory.min_erring_gate_unit == 0.1; }},
      {"trajectory.min_erring_fit_unit", 0.1,
       [](auto& o) { return o.trajectory.min_erring_fit_unit == 0.1; }},
      {"trajectory.change_lag", 7, [](auto& o) { return o.trajectory.change_lag == 7; }},
      {"trajectory.change_position_spread", 8.0,
       [](auto& o) { return o.trajectory.change_position_spread == 8.0; }},
      {"trajectory.change_velocity_spread", 3.0,
       [](auto& o) { return o.trajectory.change_velocity_spread == 3.0; }},
      {"trajectory.change_velocity_floor_fraction", 1e-3,
       [](auto& o) { return o.trajectory.change_velocity_floor_fraction == 1e-3; }},
      {"trajectory.change_position_floor_fraction", 0.0,
       [](auto& o) { return o.trajectory.change_position_floor_fraction == 0.0; }},
      {"trajectory.significance", 2.0, [](auto& o) { return o.trajectory.significance == 2.0; }},
      {"trajectory.max_history", 64, [](auto& o) { return o.trajectory.max_history == 64; }},
      {"trajectory.max_iterations", 30, [](auto& o) { return o.trajectory.max_iterations == 30; }},
      {"trajectory.step_tolerance", 1e-9,
       [](auto& o) { return o.trajectory.step_tolerance == 1e-9; }},
      {"surrogate.step_fraction", 0.04, [](auto& o) { return o.surrogate.step_fraction == 0.04; }},
      {"surrogate.quality_step_fraction", 0.03,
       [](auto& o) { return o.surrogate.quality_step_fraction == 0.03; }},
      {"surrogate.hessian_refresh", 10, [](auto& o) { return o.surrogate.hessian_refresh == 10; }},
      {"surrogate.tolerance", 2e-3, [](auto& o) { return o.surrogate.tolerance == 2e-3; }},
      {"surrogate.from_deviations", false, [](auto& o) { return !o.surrogate.from_deviations; }},
  };
  for (const Case& c : cases) {
    const std::string path = c.path;
    const std::size_t dot = path.find('.');
    const json overrides = dot == std::string::npos
                               ? json{{path, c.value}}
                               : json{{path.substr(0, dot), {{path.substr(dot + 1), c.value}}}};
    ActiveOptions options;
    ASSERT_NO_THROW(apply_active_overrides(overrides, options)) << path;
    EXPECT_TRUE(c.applied(options)) << path;
    EXPECT_FALSE(options.validate().has_value()) << path << ": " << *options.validate();
    EXPECT_EQ(active_overrides(options), overrides) << path;
  }
}

// The error's message, or "" when none is thrown.
std::string error_of(const json& overrides) {
  ActiveOptions options;
  options.regret_probe = 0.25;
  try {
    apply_active_overrides(overrides, options);
  } catch (const InvalidArgumentError& error) {
    EXPECT_EQ(options.regret_probe, 0.25) << "the options must be untouched on error";
    return error.what();
  }
  return "";
}

TEST(ApplyActiveOverrides, RefusesWhatActiveOptionsDoesNotHaveNamingTheKeyAndTheRule) {
  const std::string unknown = error_of(json::parse(R"({"regret_probe": 0.1, "regret": 1})"));
  EXPECT_NE(unknown.find("active.regret: key \"regret\" is unknown"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("regret_probe, regret_window, erring_probe_gain"), std::string::npos)
      << unknown;
  EXPECT_NE(unknown.find("trajectory, surrogate]"), std::string::npos) << unknown;
  const std::string nested = error_of(json::parse(R"({"trajectory": {"gate": 2}})"));
  EXPECT_NE(nested.find("active.trajectory.gate: key \"gate\" is unknown"), std::string::npos)
      << nested;
  const std::string owned = error_of(json::parse(R"({"measurement_variance": 1e-4})"));
  EXPECT_NE(owned.find("its own, \"measurement_variance\", beside it"), std::string::npos) << owned;
  EXPECT_NE(error_of(json::parse(R"({"initial_variance": 1e-3})")), "");
}

TEST(ApplyActiveOverrides, RefusesValuesOfTheWrongType) {
  EXPECT_NE(error_of(json::parse(R"({"audit_period": 2.5})")).find("active.audit_period: is 2.5"),
            std::string::npos);
  EXPECT_NE(error_of(json::parse(R"({"trajectory": {"max_iterations": 1e30}})")), "");
  EXPECT_NE(error_of(json::parse(R"({"weigh_model_error": 1})")).find("true or false"),
            std::string::npos);
  EXPECT_NE(error_of(json::parse(R"({"regret_probe": "0.1"})")), "");
  EXPECT_NE(error_of(json::parse(R"([1])")).find("active: is [1]; rule: must be a JSON object"),
            std::string::npos);
  EXPECT_NE(error_of(json::parse(R"({"surrogate": 3})")).find("active.surrogate: is 3"),
            std::string::npos);
  // Integers are doubles' too.
  EXPECT_EQ(error_of(json::parse(R"({"regret_probe": 1})")), "");
}

TEST(ExperimentConfigActive, IsAbsentFromTheJsonOfAConfigThatLeavesItAlone) {
  const json written = ExperimentConfig{};
  EXPECT_FALSE(written.contains("active"));
  ExperimentConfig changed;
  changed.active.trajectory.change_gate = 3.0;
  const json with = changed;
  EXPECT_EQ(with.at("active"), json::parse(R"({"trajectory": {"change_gate": 3.0}})"));
  EXPECT_NE(episode_defining_json(changed), episode_defining_json(ExperimentConfig{}));
  ExperimentConfig read;
  from_json(with, read);
  EXPECT_EQ(read.active.trajectory.change_gate, 3.0);
  from_json(json::parse(R"({"active": null})"), read);
  EXPECT_EQ(active_overrides(read.active), json::object());
}

TEST(ExperimentConfigActive, IsValidatedByItsOwnRulesNamedByTheirPath) {
  ExperimentConfig config;
  from_json(json::parse(R"({"active": {"trajectory": {"change_lag": 1}}})"), config);
  ASSERT_TRUE(config.validate().has_value());
  EXPECT_EQ(config.validate()->rfind("active.trajectory.change_lag: value is 1", 0), 0U)
      << *config.validate();
}

TEST(ExpandSweep, SetsANestedSettingByItsDottedPath) {
  const json sweep = json::parse(R"({
    "base": {"case": "analytic", "locators": "all", "active": {"regret_probe": 0.2}},
    "axes": {"active.trajectory.change_gate": [1.5, 3]}})");
  const std::vector<ExperimentGroup> groups = expand_sweep(sweep);
  ASSERT_EQ(groups.size(), 2U);
  EXPECT_EQ(groups[1].config.group_name(), "analytic/all/active.trajectory.change_gate=3");
  EXPECT_EQ(groups[0].config.active.trajectory.change_gate, 1.5);
  EXPECT_EQ(groups[1].config.active.trajectory.change_gate, 3.0);
  EXPECT_EQ(groups[1].config.active.regret_probe, 0.2);  // the base's other settings stay
  EXPECT_THROW((void)expand_sweep(json::parse(R"({"base": {"runs": 2}, "axes": {"runs.x": [1]}})")),
               InvalidArgumentError);
}

}  // namespace
}  // namespace twincal
