#pragma once
/// @file
/// `DoNoHarmAudit`: whether an estimate in doubt may correct the control, decided by the plant's
/// own answers (the active controller's "do no harm", ActiveOptions::audit_period and
/// audit_window; docs/controllers.md).
///
/// Where the estimate cannot vouch for itself — the twin's local models err, or the estimator
/// predicts the plant badly — every assembly whose correction would be applied is audited: most
/// follow the audit's verdict, every period-th is flipped to the other arm (left uncorrected
/// while the correction helps, corrected while it does not), and each audited assembly's
/// relative regret (z − z*)/z* joins its arm. The verdict: the correction helps while its mean
/// regret is no larger than doing without's, over the last `window` pairs of consecutive audited
/// assemblies of different arms — pairs compare the arms at one time, where a drift has moved
/// little, whereas the arm that is off is sampled once per period and its own regrets reach far
/// back. Until 3 pairs are in, the arms' last `window` regrets stand in; until each arm has 3,
/// the correction is trusted where the models err (the estimate weighs their errors) and the
/// arms alternate on a misfit alone (which the estimate does not explain). A correction that at
/// least halves the regret is audited four times less often.
///
/// State: two rings of `window` regrets per arm (the arms' own and the pairs'), their counts,
/// the audits so far and the last audited assembly; no allocation after construction.

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "twincal/controllers/controller_state_json.hpp"
#include "twincal/core/eigen.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/options.hpp"

namespace twincal {

class DoNoHarmAudit {
 public:
  /// An audit that flips every `period`-th audited assembly (0: no audit) and judges on the last
  /// `window` pairs.
  /// @throws InvalidArgumentError (settings_problem()).
  DoNoHarmAudit(Index period, Index window) : period_(period) {
    if (std::optional<std::string> problem = settings_problem(period, window)) {
      throw InvalidArgumentError("period and window", *problem);
    }
    for (auto& ring : regrets_)
      ring.assign(static_cast<std::size_t>(std::max<Index>(window, 0)), 0.0);
    pair_regrets_ = regrets_;
  }

  /// The rule the settings obey, in the options' message format, its fields named as the owner
  /// names them (ActiveOptions: audit_period, audit_window).
  [[nodiscard]] static std::optional<std::string> settings_problem(
      Index period, Index window, std::string_view period_name = "period",
      std::string_view window_name = "window") {
    return rule::check_fields(
        period == 0 || (period >= 2 && window >= 3),
        fmt::format("{} and {}", period_name, window_name), std::array{period, window},
        "{0} = 0 (no audit), or {0} >= 2 and {1} >= 3", period_name, window_name);
  }

  /// The arm of an assembly whose correction would be applied: nothing where the estimate is not
  /// in `doubt` or the audit is off; false for one `held_back` by another rule (it joins the
  /// uncorrected arm, and is not counted as an audit); otherwise whether it is corrected.
  /// `erring_model`: the doubt comes from the twin's local models (the estimate weighs their
  /// errors, so it is trusted until the arms are measured), not from a misfit alone.
  [[nodiscard]] std::optional<bool> decide(bool doubt, bool erring_model, bool held_back) {
    if (!doubt || period_ <= 0) return std::nullopt;
    if (held_back) return false;  // an uncorrected sample all the same
    ++audits_;
    const std::optional<std::array<double, 2>> arms = means();
    if (!arms && !erring_model) return audits_ % 2 == 1;
    const bool helps = !arms || (*arms)[1] <= (*arms)[0];
    const bool clear = arms && (*arms)[1] <= 0.5 * (*arms)[0];
    const auto period = static_cast<std::uint64_t>(period_ * (clear ? 4 : 1));
    const bool flip = audits_ % period == 0;
    return helps != flip;
  }

  /// Records the relative regret (z − z*)/z* of the audited assembly `time` (≥ 0; one call per
  /// assembly, in order), `corrected` or not; it pairs with the audited assembly just before it
  /// when that one was of the other arm. An audit that is off keeps nothing.
  void record(Index time, bool corrected, double regret) {
    if (period_ <= 0) return;
    const std::size_t arm = corrected ? 1 : 0;
    regrets_[arm][counts_[arm] % regrets_[arm].size()] = regret;
    ++counts_[arm];
    if (last_.time >= 0 && last_.time == time - 1 && last_.corrected != corrected) {
      const std::size_t at = pairs_ % pair_regrets_[arm].size();
      pair_regrets_[arm][at] = regret;
      pair_regrets_[1 - arm][at] = last_.regret;
      ++pairs_;
    }
    last_ = {time, corrected, regret};
  }

  /// The mean relative regrets, uncorrected [0] and corrected [1], over the kept pairs once there
  /// are 3; before that over each arm's kept regrets; nothing while either arm has fewer than 3.
  [[nodiscard]] std::optional<std::array<double, 2>> means() const noexcept {
    const bool paired = pairs_ >= 3;
    std::array<double, 2> means{};
    for (std::size_t arm = 0; arm < 2; ++arm) {
      const std::vector<double>& ring = paired ? pair_regrets_[arm] : regrets_[arm];
      const std::size_t kept = std::min(ring.size(), paired ? pairs_ : counts_[arm]);
      if (kept < 3) return std::nullopt;
      for (std::size_t i = 0; i < kept; ++i) means[arm] += ring[i];
      means[arm] /= static_cast<double>(kept);
    }
    return means;
  }

  /// Audits decided so far (held-back assemblies not counted).
  [[nodiscard]] std::uint64_t audits() const noexcept { return audits_; }

  /// Writes the state into the owner's snapshot `saved` (its fields "regrets", "audit_counts",
  /// "audits" and "audit_pairs").
  void save(nlohmann::json& saved) const {
    using json_state::doubles_to_json;
    saved["regrets"] = {doubles_to_json(regrets_[0]), doubles_to_json(regrets_[1])};
    saved["audit_counts"] = {counts_[0], counts_[1]};
    saved["audits"] = audits_;
    saved["audit_pairs"] = {
        {"regrets", {doubles_to_json(pair_regrets_[0]), doubles_to_json(pair_regrets_[1])}},
        {"count", pairs_},
        {"last_time", last_.time},
        {"last_corrected", last_.corrected},
        {"last_regret", json_state::number_to_json(last_.regret)}};
  }

  /// Restores the state save() wrote into `saved`, all or nothing.
  /// @throws InvalidArgumentError, NonFiniteError naming the field ("audit_pairs.regrets[1]").
  void restore(const nlohmann::json& saved) {
    using json_state::field;
    DoNoHarmAudit restored = *this;
    const nlohmann::json& regrets =
        json_state::require_array(field(saved, "regrets"), "regrets", 2);
    const nlohmann::json& counts =
        json_state::require_array(field(saved, "audit_counts"), "audit_counts", 2);
    for (std::size_t arm = 0; arm < 2; ++arm) {
      json_state::read_doubles(regrets[arm], fmt::format("regrets[{}]", arm),
                               restored.regrets_[arm]);
      restored.counts_[arm] = static_cast<std::size_t>(
          json_state::read_integer(counts[arm], fmt::format("audit_counts[{}]", arm), 0));
    }
    restored.audits_ = json_state::read_count(saved, "audits");
    const nlohmann::json& pairs = field(saved, "audit_pairs");
    json_state::within("audit_pairs", [&] {
      const nlohmann::json& rings =
          json_state::require_array(field(pairs, "regrets"), "regrets", 2);
      for (std::size_t arm = 0; arm < 2; ++arm) {
        json_state::read_doubles(rings[arm], fmt::format("regrets[{}]", arm),
                                 restored.pair_regrets_[arm]);
      }
      restored.last_.time = json_state::read_integer_field(pairs, "last_time", -1);
      restored.last_.corrected = json_state::read_bool(pairs, "last_corrected");
      restored.last_.regret = json_state::read_double_field(pairs, "last_regret");
      restored.pairs_ = static_cast<std::size_t>(json_state::read_count(pairs, "count"));
    });
    *this = std::move(restored);
  }

 private:
  // The last audited assembly (time −1: none yet).
  struct AuditedAssembly {
    Index time = -1;
    bool corrected = false;
    double regret = 0.0;
  };

  Index period_ = 0;
  std::array<std::vector<double>, 2> regrets_;  // rings: [0] uncorrected, [1] corrected
  std::array<std::size_t, 2> counts_{};
  std::uint64_t audits_ = 0;
  std::array<std::vector<double>, 2> pair_regrets_;  // rings of the pairs, as regrets_
  std::size_t pairs_ = 0;
  AuditedAssembly last_;
};

}  // namespace twincal
