// write_episode_trace: the episode of run_episode, digit for digit, with one CSV row per
// assembly whose columns say what the plant and the controller did; the active controller's
// step report in its columns; a controller that reports nothing more gets the common columns.
#include "twincal/experiments/episode_trace.hpp"

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "twincal/experiments/episode_runner.hpp"
#include "twincal/experiments/twin_cases.hpp"

namespace twincal {
namespace {

ExperimentConfig trace_config() {
  ExperimentConfig config;
  config.twin_case = TwinCase::analytic;
  config.analytic_dimension = 3;
  config.locators = "all";
  config.nonlinearity = Nonlinearity::contact;
  config.assemblies = 25;
  config.runs = 2;
  return config;
}

std::vector<std::string> split(const std::string& text, char separator) {
  std::vector<std::string> parts;
  std::stringstream in(text);
  std::string part;
  while (std::getline(in, part, separator)) parts.push_back(part);
  return parts;
}

// The column `name` of a header.
std::size_t column(const std::vector<std::string>& header, const std::string& name) {
  for (std::size_t i = 0; i < header.size(); ++i) {
    if (header[i] == name) return i;
  }
  ADD_FAILURE() << "no column " << name;
  return 0;
}

TEST(EpisodeTrace, IsTheEpisodeOfRunEpisodeWithOneRowPerAssembly) {
  const ExperimentConfig config = trace_config();
  const CaseTwin twin = make_case_twin(config);
  std::ostringstream out;
  const EpisodeResult traced = write_episode_trace(twin, config, ControllerSpec::active(), 1, out);
  const EpisodeResult plain = run_episode(twin, config, ControllerSpec::active(), 1);
  EXPECT_EQ(traced.z, plain.z);
  EXPECT_EQ(traced.estimate, plain.estimate);
  EXPECT_EQ(traced.q_evaluations, plain.q_evaluations);
  EXPECT_EQ(traced.lost, plain.lost);

  const std::vector<std::string> lines = split(out.str(), '\n');
  ASSERT_EQ(lines.size(), static_cast<std::size_t>(traced.steps) + 1);
  const std::vector<std::string> header = split(lines[0], ',');
  EXPECT_EQ(lines[0].rfind(episode_trace_columns, 0), 0U) << lines[0];
  for (const char* key :
       {"change_ratio", "misfit_scale", "prediction_scale", "velocity_change", "corrected",
        "held_by_surprises", "held_by_audit", "model_error", "probe_norm", "normalized_residual"}) {
    (void)column(header, key);
  }
  for (Index t = 0; t < traced.steps; ++t) {
    const std::vector<std::string> row = split(lines[static_cast<std::size_t>(t) + 1], ',');
    ASSERT_EQ(row.size(), header.size()) << "assembly " << t;
    EXPECT_EQ(std::stoll(row[column(header, "t")]), t);
    EXPECT_EQ(std::stoll(row[column(header, "upper")]),
              traced.assemblies[static_cast<std::size_t>(t)].upper);
    // Numbers in their shortest exact form: they read back to the result's.
    EXPECT_EQ(std::stod(row[column(header, "z")]), traced.z(t));
    EXPECT_EQ(std::stod(row[column(header, "estimation_error")]),
              (traced.estimate.col(t) - traced.offset.col(t)).norm());
    EXPECT_EQ(std::stod(row[column(header, "q_evaluations")]), traced.q_evaluations(t));
    const std::string& corrected = row[column(header, "corrected")];
    EXPECT_TRUE(corrected == "true" || corrected == "false") << corrected;
    // The estimator ran (the twin's models are quadratic ones, weighed by their error).
    EXPECT_GE(std::stod(row[column(header, "misfit_scale")]), 1.0) << "assembly " << t;
  }
  // The gate is consulted once the history is long enough.
  EXPECT_NE(split(lines.back(), ',')[column(header, "change_ratio")], "nan");
}

TEST(EpisodeTrace, GivesAControllerThatReportsNothingMoreTheCommonColumns) {
  const ExperimentConfig config = trace_config();
  const CaseTwin twin = make_case_twin(config);
  std::ostringstream out;
  const EpisodeResult traced =
      write_episode_trace(twin, config, ControllerSpec::baseline(), 0, out);
  const std::vector<std::string> lines = split(out.str(), '\n');
  ASSERT_EQ(lines.size(), static_cast<std::size_t>(traced.steps) + 1);
  EXPECT_EQ(lines[0], episode_trace_columns);
  // The baseline does not estimate: δû = 0, so its error is ‖δu*‖, and tr P is NaN.
  const std::vector<std::string> header = split(lines[0], ',');
  const std::vector<std::string> last = split(lines.back(), ',');
  EXPECT_EQ(last[column(header, "estimation_error")], last[column(header, "offset_norm")]);
  EXPECT_EQ(last[column(header, "trace_p")], "nan");
}

}  // namespace
}  // namespace twincal
