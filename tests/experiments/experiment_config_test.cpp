#include "twincal/experiments/experiment_config.hpp"

#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "twincal/core/error.hpp"

namespace twincal {
namespace {

TEST(ExperimentConfig, DefaultsAreThePapersAndValid) {
  const ExperimentConfig config;
  EXPECT_FALSE(config.validate().has_value());
  EXPECT_EQ(config.runs, 10);
  EXPECT_EQ(config.assemblies, 100);
  EXPECT_EQ(config.controllers.size(), 14U);
  EXPECT_EQ(config.filter_measurement_variance(), 1e-4);
  ExperimentConfig door;
  door.twin_case = TwinCase::door;
  EXPECT_EQ(door.filter_measurement_variance(), 1e-6);
  EXPECT_EQ(config.group_name(), "body/A");
}

TEST(ExperimentConfig, RoundTripsThroughJson) {
  ExperimentConfig config;
  config.name = "trial";
  config.twin_case = TwinCase::analytic;
  config.analytic_dimension = 5;
  config.locators = "A,C";
  config.controllers = {ControllerSpec::nominal(), ControllerSpec::lookahead(0.7)};
  config.filter = FilterScheme::cubature;
  config.sampler = CandidateSampler::halton;
  config.exploration = ExplorationKind::log_det;
  config.candidates = 12;
  config.candidate_cap = 10;
  config.measurement_variance = 3e-5;
  config.plant_noise_variance = 1e-6;
  config.seed = 99;
  config.stop_on_divergence = false;
  config.twin_failure_streak = 9;
  const nlohmann::json json = config;
  const ExperimentConfig back = json.get<ExperimentConfig>();
  EXPECT_EQ(nlohmann::json(back), json);
  EXPECT_EQ(back.controllers, config.controllers);
  EXPECT_EQ(back.candidates, config.candidates);
  EXPECT_EQ(back.candidate_cap, config.candidate_cap);
  EXPECT_EQ(back.measurement_variance, config.measurement_variance);
  EXPECT_EQ(back.filter, FilterScheme::cubature);
  EXPECT_EQ(back.twin_failure_streak, 9);
}

TEST(ExperimentConfig, RoundTripsTheNonlinearityAndThePlant) {
  ExperimentConfig config;
  config.twin_case = TwinCase::analytic;
  config.nonlinearity = Nonlinearity::stiffening;
  config.strength = 1.5;
  const ExperimentConfig back = nlohmann::json(config).get<ExperimentConfig>();
  EXPECT_EQ(back.nonlinearity, Nonlinearity::stiffening);
  EXPECT_EQ(back.strength, 1.5);
  EXPECT_EQ(nlohmann::json(config).at("plant_case"), nullptr);
  config.nonlinearity = Nonlinearity::none;
  config.plant_nonlinearity = Nonlinearity::contact;
  config.plant_strength = 0.5;
  ASSERT_FALSE(config.validate().has_value()) << *config.validate();
  const ExperimentConfig plant = nlohmann::json(config).get<ExperimentConfig>();
  EXPECT_EQ(plant.plant_nonlinearity, Nonlinearity::contact);
  EXPECT_EQ(plant.plant_strength, 0.5);
  ExperimentConfig fem;
  fem.plant_case = TwinCase::door;
  EXPECT_EQ(nlohmann::json(fem).get<ExperimentConfig>().plant_case, TwinCase::door);
}

TEST(ExperimentConfig, RefusesANonlinearityOrPlantWhereItCannotBe) {
  ExperimentConfig config;
  config.nonlinearity = Nonlinearity::kink;  // case body
  ASSERT_TRUE(config.validate().has_value());
  EXPECT_NE(config.validate()->find("only the analytic case takes a nonlinearity"),
            std::string::npos);
  config = {};
  config.twin_case = TwinCase::analytic;
  config.nonlinearity = Nonlinearity::contact;
  config.strength = 1.5;
  ASSERT_TRUE(config.validate().has_value());
  EXPECT_NE(config.validate()->find("strength: value is 1.5; rule: must be finite and >= 0, and <= "
                                    "1 with the contact nonlinearity"),
            std::string::npos);
  config = {};
  config.plant_nonlinearity = Nonlinearity::contact;  // case body
  EXPECT_TRUE(config.validate().has_value());
  config = {};
  config.twin_case = TwinCase::analytic;
  config.plant_case = TwinCase::body;
  EXPECT_TRUE(config.validate().has_value());
  config = {};
  config.twin_case = TwinCase::analytic;
  config.plant_strength = 0.5;
  ASSERT_TRUE(config.validate().has_value());
  EXPECT_NE(config.validate()->find("plant_strength: value is "), std::string::npos);
}

TEST(ExperimentConfig, ReadsPartialDocumentsAndLocatorLists) {
  const auto config = nlohmann::json::parse(R"({"case": "door", "locators": ["L1", 4],
                                                "controllers": "paper", "runs": 3})")
                          .get<ExperimentConfig>();
  EXPECT_EQ(config.twin_case, TwinCase::door);
  EXPECT_EQ(config.locators, "L1,4");
  EXPECT_EQ(config.runs, 3);
  EXPECT_EQ(config.assemblies, 100);
}

TEST(ExperimentConfig, RejectsUnknownKeysAndWrongTypesNamingThem) {
  try {
    (void)nlohmann::json::parse(R"({"rnus": 3})").get<ExperimentConfig>();
    FAIL() << "no error";
  } catch (const InvalidArgumentError& error) {
    EXPECT_EQ(error.argument(), "rnus");
  }
  EXPECT_THROW((void)nlohmann::json::parse(R"({"runs": "many"})").get<ExperimentConfig>(),
               InvalidArgumentError);
  EXPECT_THROW((void)nlohmann::json::parse(R"({"filter": "ukf"})").get<ExperimentConfig>(),
               InvalidArgumentError);
}

// Integer fields take JSON integers in range; nothing is coerced (2.9 was read as 2, −5 as a
// seed of 2⁶⁴ − 5, 1e30 as a negative count).
TEST(ExperimentConfig, IntegerFieldsRefuseWhatTheyWouldHaveCoerced) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {R"({"runs": 2.9})", "runs: is 2.9; rule: an integer"},
      {R"({"runs": 1e30})", "runs: is 1e+30; rule: an integer"},
      {R"({"analytic_dimension": 3.9})", "analytic_dimension: is 3.9; rule: an integer"},
      {R"({"seed": -5})", "seed: is -5; rule: a non-negative integer"},
      {R"({"seed": 7.5})", "seed: is 7.5; rule: a non-negative integer"},
      {R"({"runs": 9223372036854775808})",
       "runs: is 9223372036854775808; rule: an integer in [-9223372036854775808, "
       "9223372036854775807]"},
  };
  for (const auto& [text, message] : cases) {
    try {
      static_cast<void>(nlohmann::json::parse(text).get<ExperimentConfig>());
      ADD_FAILURE() << text << " was accepted";
    } catch (const InvalidArgumentError& error) {
      EXPECT_NE(std::string(error.what()).find(message), std::string::npos)
          << text << ": " << error.what();
    }
  }
  const ExperimentConfig exact =
      nlohmann::json::parse(R"({"runs": 3, "seed": 18446744073709551615})").get<ExperimentConfig>();
  EXPECT_EQ(exact.runs, 3);
  EXPECT_EQ(exact.seed, 18446744073709551615ULL);
}

TEST(ExperimentConfig, ValidateNamesTheBrokenField) {
  ExperimentConfig config;
  config.runs = 0;
  ASSERT_TRUE(config.validate().has_value());
  EXPECT_NE(config.validate()->find("runs: value is 0"), std::string::npos);
  // A count whose episodes overflow (it printed "-2 episodes") is refused, not wrapped.
  config.runs = std::numeric_limits<Index>::max();
  EXPECT_EQ(config.validate(),
            "runs: value is 9223372036854775807; rule: must lie in [1, 1000000]");
  config = {};
  config.controllers = {ControllerSpec::default_controller(), ControllerSpec::default_controller()};
  ASSERT_TRUE(config.validate().has_value());
  EXPECT_NE(config.validate()->find("value is \"default\"; rule: each controller at most once"),
            std::string::npos);
  config = {};
  config.measurement_variance = 0.0;
  EXPECT_TRUE(config.validate().has_value());
  config = {};
  config.name = "a,b";
  EXPECT_TRUE(config.validate().has_value());
  config = {};
  config.analytic_dimension = 100000;  // a d x d curvature of 80 GB
  ASSERT_TRUE(config.validate().has_value());
  EXPECT_NE(
      config.validate()->find("analytic_dimension: value is 100000; rule: must lie in [1, 1024]"),
      std::string::npos);
  config = {};
  config.twin_failure_streak = 0;
  ASSERT_TRUE(config.validate().has_value());
  EXPECT_NE(config.validate()->find("twin_failure_streak: value is 0"), std::string::npos);
}

TEST(ExperimentConfig, CandidateCountIsThePapersOrTheSetCountCapped) {
  ExperimentConfig config;
  EXPECT_EQ(config.candidate_count(3), 32);
  EXPECT_EQ(config.candidate_count(100), Index{1} << 62);  // saturates instead of overflowing
  config.candidate_cap = 1024;
  EXPECT_EQ(config.candidate_count(6), 256);
  EXPECT_EQ(config.candidate_count(19), 1024);
  config.candidates = 2000;
  EXPECT_EQ(config.candidate_count(1), 1024);
  config.candidate_cap = 0;
  ASSERT_TRUE(config.validate().has_value());
  EXPECT_NE(config.validate()->find("candidate_cap: value is 0"), std::string::npos);
  config.candidate_cap.reset();
  config.controllers = {ControllerSpec::per_component(1.5)};
  ASSERT_TRUE(config.validate().has_value());
  EXPECT_NE(config.validate()->find("controllers[0].w: value is 1.5; rule: must lie in [0, 1]"),
            std::string::npos);
}

TEST(ExperimentConfig, EpisodeDefiningJsonIgnoresNameRunsControllersAndTheTwinFailureStreak) {
  ExperimentConfig a;
  ExperimentConfig b;
  b.name = "other";
  b.runs = 20;
  b.controllers = {ControllerSpec::baseline()};
  b.twin_failure_streak = 2;  // whether a failed episode is stored, not what a stored one holds
  EXPECT_EQ(episode_defining_json(a), episode_defining_json(b));
  b.measurement_variance = 1e-4;  // the body's default, spelled out
  EXPECT_EQ(episode_defining_json(a), episode_defining_json(b));
  b.seed = 1;
  EXPECT_NE(episode_defining_json(a), episode_defining_json(b));
}

}  // namespace
}  // namespace twincal
