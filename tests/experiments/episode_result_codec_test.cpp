#include "twincal/experiments/episode_result_codec.hpp"

#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "twincal/core/error.hpp"
#include "twincal/experiments/episode_runner.hpp"
#include "twincal/experiments/result_store.hpp"
#include "twincal/experiments/twin_cases.hpp"

namespace twincal {
namespace {

ExperimentConfig codec_config() {
  ExperimentConfig config;
  config.twin_case = TwinCase::analytic;
  config.locators = "ABC";
  config.assemblies = 15;
  config.runs = 1;
  return config;
}

// Equal entry by entry, NaN equal to NaN (what the stored files see).
template <typename Derived>
void expect_same_numbers(const Eigen::DenseBase<Derived>& a, const Eigen::DenseBase<Derived>& b,
                         const char* what) {
  ASSERT_EQ(a.rows(), b.rows()) << what;
  ASSERT_EQ(a.cols(), b.cols()) << what;
  for (Index j = 0; j < a.cols(); ++j) {
    for (Index i = 0; i < a.rows(); ++i) {
      if (std::isnan(a(i, j))) {
        EXPECT_TRUE(std::isnan(b(i, j))) << what << " (" << i << ", " << j << ")";
      } else {
        EXPECT_EQ(a(i, j), b(i, j)) << what << " (" << i << ", " << j << ")";
      }
    }
  }
}

void expect_same_result(const EpisodeResult& a, const EpisodeResult& b) {
  EXPECT_EQ(a.group, b.group);
  EXPECT_EQ(a.controller, b.controller);
  EXPECT_EQ(a.run, b.run);
  EXPECT_EQ(a.run_seed, b.run_seed);
  ASSERT_EQ(a.steps, b.steps);
  EXPECT_EQ(a.assemblies, b.assemblies);
  expect_same_numbers(a.z, b.z, "z");
  expect_same_numbers(a.z_star, b.z_star, "z_star");
  expect_same_numbers(a.control, b.control, "control");
  expect_same_numbers(a.estimate, b.estimate, "estimate");
  expect_same_numbers(a.offset, b.offset, "offset");
  expect_same_numbers(a.trace_p, b.trace_p, "trace_p");
  expect_same_numbers(a.q_evaluations, b.q_evaluations, "q_evaluations");
  expect_same_numbers(a.seconds, b.seconds, "seconds");
  // The stored line holds every metric: equal lines, equal metrics (NaN as null).
  EXPECT_EQ(episode_metrics_json(a).dump(), episode_metrics_json(b).dump());
  EXPECT_EQ(a.lost, b.lost);
  EXPECT_EQ(a.failure, b.failure);
  EXPECT_EQ(a.fallbacks, b.fallbacks);
  EXPECT_EQ(a.dropped_measurements, b.dropped_measurements);
  EXPECT_EQ(a.first_fallback_at, b.first_fallback_at);
  EXPECT_EQ(a.first_fallback, b.first_fallback);
}

TEST(EpisodeResultCodec, AnEpisodeReadsBackToTheSameNumbers) {
  const ExperimentConfig config = codec_config();
  const CaseTwin twin = make_case_twin(config);
  for (const ControllerSpec& spec :
       {ControllerSpec::baseline(), ControllerSpec::lookahead(1.0), ControllerSpec::active()}) {
    const EpisodeResult result = run_episode(twin, config, spec, 0);
    ASSERT_GT(result.steps, 0);
    expect_same_result(result, decode_episode_result(encode_episode_result(result)));
  }
}

TEST(EpisodeResultCodec, KeepsNanInfinitySignedZeroAFailureAndAFallback) {
  EpisodeResult result;
  result.group = "g";
  result.controller = "w=1";
  result.run = 7;
  result.run_seed = std::numeric_limits<std::uint64_t>::max();
  result.steps = 2;
  result.assemblies = {{0, 1}, {2, 3}};
  result.z = VectorX{{0.1, std::numeric_limits<double>::quiet_NaN()}};
  result.z_star = VectorX{{-0.0, std::numeric_limits<double>::infinity()}};
  result.control = MatrixX{{1e-300, 2.0}, {3.0, 1.0 / 3.0}};
  result.estimate = MatrixX::Zero(2, 2);
  result.offset = MatrixX::Constant(2, 2, 0.25);
  result.trace_p = VectorX::Constant(2, std::numeric_limits<double>::quiet_NaN());
  result.q_evaluations = VectorX{{3.0, 4.0}};
  result.seconds = VectorX{{1e-6, 2e-6}};
  result.diverged_at = 1;
  result.failure = "Cholesky: P is not positive definite";
  result.estimate_error_second_half = std::numeric_limits<double>::quiet_NaN();
  result.lost = true;
  result.fallbacks = 1;
  result.dropped_measurements = 2;
  result.first_fallback_at = 0;
  result.first_fallback = "proposal: twin: no reply within 5 s";
  const EpisodeResult back = decode_episode_result(encode_episode_result(result));
  expect_same_result(result, back);
  EXPECT_TRUE(std::signbit(back.z_star(0)));
  EXPECT_EQ(back.diverged_at, 1);
}

TEST(EpisodeResultCodec, AnEncodingThatIsNotOneIsAnError) {
  const std::vector<std::uint8_t> garbage{0x01, 0x02, 0x03};
  EXPECT_THROW((void)decode_episode_result(garbage), Error);
  EXPECT_THROW((void)decode_episode_result({}), Error);
  // A valid encoding edited so that its trace does not match `steps`.
  EpisodeResult result;
  result.steps = 1;
  result.assemblies = {{0, 0}};
  result.z = result.z_star = result.trace_p = result.q_evaluations = result.seconds =
      VectorX::Zero(1);
  result.control = result.estimate = result.offset = MatrixX::Zero(2, 1);
  const std::vector<std::uint8_t> bytes = encode_episode_result(result);
  EXPECT_NO_THROW((void)decode_episode_result(bytes));
  nlohmann::json edited = nlohmann::json::from_cbor(bytes);
  edited["control"]["cols"] = 2;
  try {
    (void)decode_episode_result(nlohmann::json::to_cbor(edited));
    ADD_FAILURE() << "a matrix whose data does not fill its size was accepted";
  } catch (const Error& error) {
    EXPECT_THAT(error.what(), ::testing::HasSubstr("episode result:"));
  }
  edited = nlohmann::json::from_cbor(bytes);
  edited["steps"] = 2;
  EXPECT_THROW((void)decode_episode_result(nlohmann::json::to_cbor(edited)), Error);
}

}  // namespace
}  // namespace twincal
