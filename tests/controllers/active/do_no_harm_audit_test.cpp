#include "twincal/controllers/active/do_no_harm_audit.hpp"

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "twincal/core/error.hpp"

namespace twincal {
namespace {

// The arms of `count` audits in a row.
std::vector<bool> decisions(DoNoHarmAudit& audit, int count, bool erring_model) {
  std::vector<bool> arms;
  for (int i = 0; i < count; ++i) {
    const std::optional<bool> arm = audit.decide(true, erring_model, false);
    EXPECT_TRUE(arm.has_value());
    arms.push_back(arm.value_or(false));
  }
  return arms;
}

// `count` pairs of consecutive audited assemblies from `time` on: corrected, then not.
void record_pairs(DoNoHarmAudit& audit, Index& time, int count, double corrected,
                  double uncorrected) {
  for (int i = 0; i < count; ++i) {
    audit.record(time++, true, corrected);
    audit.record(time++, false, uncorrected);
  }
}

TEST(DoNoHarmAudit, AuditsNothingWithoutDoubtOrWithoutAPeriod) {
  DoNoHarmAudit audit(10, 10);
  EXPECT_EQ(audit.decide(false, false, false), std::nullopt);
  EXPECT_EQ(audit.decide(false, false, true), std::nullopt);
  DoNoHarmAudit off(0, 0);
  EXPECT_EQ(off.decide(true, true, false), std::nullopt);
  for (Index t = 0; t < 8; ++t) off.record(t, t % 2 == 0, 1.0);  // keeps nothing
  EXPECT_EQ(off.means(), std::nullopt);
  EXPECT_EQ(audit.audits(), 0U);
  EXPECT_EQ(off.audits(), 0U);
}

TEST(DoNoHarmAudit, AHeldBackAssemblyIsAnUncorrectedSampleAndNotAnAudit) {
  DoNoHarmAudit audit(10, 10);
  EXPECT_EQ(audit.decide(true, true, true), std::optional<bool>(false));
  EXPECT_EQ(audit.audits(), 0U);
}

// Before the arms are measured, an estimate that weighs its models' errors is trusted, with
// every period-th assembly flipped; on a misfit alone the arms alternate.
TEST(DoNoHarmAudit, TrustsAnErringModelsEstimateAndAlternatesOnAMisfitAloneUntilMeasured) {
  DoNoHarmAudit erring(5, 10);
  const std::vector<bool> arms = decisions(erring, 10, true);
  for (std::size_t i = 0; i < 10; ++i) EXPECT_EQ(arms[i], (i + 1) % 5 != 0) << i;
  DoNoHarmAudit misfit(5, 10);
  const std::vector<bool> alternating = decisions(misfit, 6, false);
  for (std::size_t i = 0; i < 6; ++i) EXPECT_EQ(alternating[i], i % 2 == 0) << i;
}

// Measured: the verdict follows the pairs' means, and the period-th audit samples the other arm,
// four times less often for a correction that at least halves the regret.
TEST(DoNoHarmAudit, FollowsThePairsAndAuditsAClearCorrectionFourTimesLessOften) {
  Index time = 0;
  DoNoHarmAudit harmful(5, 10);
  record_pairs(harmful, time, 3, 0.3, 0.2);
  ASSERT_TRUE(harmful.means().has_value());
  EXPECT_DOUBLE_EQ((*harmful.means())[0], 0.2);
  EXPECT_DOUBLE_EQ((*harmful.means())[1], 0.3);
  const std::vector<bool> off = decisions(harmful, 10, true);
  for (std::size_t i = 0; i < 10; ++i) EXPECT_EQ(off[i], (i + 1) % 5 == 0) << i;

  DoNoHarmAudit helps(5, 10);
  record_pairs(helps, time, 3, 0.15, 0.2);  // helps, but less than half
  const std::vector<bool> on = decisions(helps, 10, false);
  for (std::size_t i = 0; i < 10; ++i) EXPECT_EQ(on[i], (i + 1) % 5 != 0) << i;

  DoNoHarmAudit clear(5, 10);
  record_pairs(clear, time, 3, 0.1, 0.2);  // halves it
  const std::vector<bool> rare = decisions(clear, 40, true);
  for (std::size_t i = 0; i < 40; ++i) EXPECT_EQ(rare[i], (i + 1) % 20 != 0) << i;
}

// Only consecutive assemblies of different arms pair; until 3 pairs are in, each arm's own
// regrets stand in, and nothing while either arm has fewer than 3.
TEST(DoNoHarmAudit, PairsOnlyConsecutiveAssembliesOfDifferentArms) {
  DoNoHarmAudit audit(5, 10);
  audit.record(0, true, 1.0);
  audit.record(2, false, 4.0);  // not consecutive: no pair
  audit.record(3, false, 4.0);  // the same arm: no pair
  audit.record(4, true, 1.0);   // pairs with 3
  audit.record(6, true, 2.0);
  EXPECT_EQ(audit.means(), std::nullopt);  // 2 uncorrected so far
  audit.record(8, false, 4.0);             // not consecutive
  ASSERT_TRUE(audit.means().has_value());  // one pair: the arms' own regrets stand in
  EXPECT_DOUBLE_EQ((*audit.means())[0], 4.0);
  EXPECT_DOUBLE_EQ((*audit.means())[1], (1.0 + 1.0 + 2.0) / 3.0);
  audit.record(9, true, 0.0);    // pairs with 8
  audit.record(10, false, 3.0);  // pairs with 9
  ASSERT_TRUE(audit.means().has_value());
  // Three pairs, uncorrected | corrected: 4 | 1 (3, 4), 4 | 0 (8, 9), 3 | 0 (9, 10).
  EXPECT_DOUBLE_EQ((*audit.means())[0], (4.0 + 4.0 + 3.0) / 3.0);
  EXPECT_DOUBLE_EQ((*audit.means())[1], 1.0 / 3.0);
}

// The window keeps the last pairs: old ones leave the ring.
TEST(DoNoHarmAudit, JudgesOnTheLastWindowOfPairs) {
  Index time = 0;
  DoNoHarmAudit audit(5, 3);
  record_pairs(audit, time, 3, 0.9, 0.1);
  record_pairs(audit, time, 3, 0.1, 0.9);
  ASSERT_TRUE(audit.means().has_value());
  EXPECT_DOUBLE_EQ((*audit.means())[1], 0.1);
  EXPECT_DOUBLE_EQ((*audit.means())[0], 0.9);
}

TEST(DoNoHarmAudit, RestoresWhatItSavedAndDecidesAlike) {
  Index time = 0;
  DoNoHarmAudit audit(4, 5);
  record_pairs(audit, time, 2, 0.3, 0.5);
  audit.record(time++, true, 0.25);
  (void)decisions(audit, 3, true);
  nlohmann::json saved;
  audit.save(saved);
  DoNoHarmAudit restored(4, 5);
  restored.restore(saved);
  nlohmann::json again;
  restored.save(again);
  EXPECT_EQ(again, saved);
  EXPECT_EQ(restored.audits(), audit.audits());
  EXPECT_EQ(restored.means(), audit.means());
  audit.record(time, false, 0.4);
  restored.record(time, false, 0.4);
  EXPECT_EQ(decisions(restored, 12, true), decisions(audit, 12, true));
}

TEST(DoNoHarmAudit, RefusesABrokenSnapshotNamingTheFieldAndKeepsItsState) {
  Index time = 0;
  DoNoHarmAudit audit(4, 5);
  record_pairs(audit, time, 3, 0.3, 0.5);
  nlohmann::json saved;
  audit.save(saved);
  const std::array<std::pair<std::string, std::string>, 3> breaks{
      {{"regrets", "regrets[1]"}, {"audit_pairs", "audit_pairs.regrets[1]"}, {"audits", "audits"}}};
  for (const auto& [field, name] : breaks) {
    nlohmann::json broken = saved;
    if (field == "regrets") broken["regrets"][1] = {1.0};  // a ring of another size
    if (field == "audit_pairs") broken["audit_pairs"]["regrets"][1] = {1.0, 2.0};
    if (field == "audits") broken["audits"] = -1;
    DoNoHarmAudit target(4, 5);
    try {
      target.restore(broken);
      ADD_FAILURE() << name << " was accepted";
    } catch (const Error& error) {
      EXPECT_EQ(error.argument(), name) << error.what();
    }
    EXPECT_EQ(target.means(), std::nullopt) << name;  // unchanged
    EXPECT_EQ(target.audits(), 0U) << name;
  }
}

TEST(DoNoHarmAudit, RefusesAPeriodOfOneAndAShortWindow) {
  EXPECT_THROW(DoNoHarmAudit(1, 10), InvalidArgumentError);
  EXPECT_THROW(DoNoHarmAudit(-2, 10), InvalidArgumentError);
  EXPECT_THROW(DoNoHarmAudit(10, 2), InvalidArgumentError);
  EXPECT_NO_THROW(DoNoHarmAudit(0, 0));
}

}  // namespace
}  // namespace twincal
