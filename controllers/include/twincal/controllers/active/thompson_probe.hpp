#pragma once
/// @file
/// `ThompsonProbe<N>`: a probe drawn from the offset's posterior, p = s · L ξ with P = L Lᵀ and
/// ξ ~ N(0, I) — Thompson sampling (Russo & Van Roy, Oper. Res. 66(1), 2018) shrunk by s. The
/// probe excites every direction in proportion to what is still unknown there, so it fades by
/// itself as the estimate sharpens, and its expected quality cost is s² tr(HP): a fixed fraction
/// of the cost of the uncertainty itself, whatever the twin's scales. Probes are clipped to
/// max_probe per locator. The draws come from a seeded stream (reseed() from the controller).
///
/// Cost per call: one Cholesky factorization of P (O(d³)); no allocation after the first call at
/// a size.

#include <cmath>
#include <optional>
#include <string_view>

#include <fmt/format.h>
#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "twincal/controllers/active/probe_design.hpp"
#include "twincal/controllers/controller_state_json.hpp"
#include "twincal/core/eigen.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/random_stream.hpp"

namespace twincal {

template <int N = Dynamic>
class ThompsonProbe {
 public:
  /// The default shrinkage, s = 0.025: the probes add 0.06 % of the uncertainty's quality cost.
  /// Where the offset barely moves the quality (the door, below σz) every probe is pure cost;
  /// where it matters with many locators (d = 32) probes are the only information. 0.02 gave
  /// the door room but left the analytic twin at d = 32 on the edge of its target, 0.03 the
  /// reverse; 0.025 meets both over 8 seed pairs (docs/reproduction.md).
  ThompsonProbe() : ThompsonProbe(0.025) {}

  /// Draws with shrinkage `scale` in (0, 1] from `stream`.
  /// @throws InvalidArgumentError for a scale outside (0, 1].
  explicit ThompsonProbe(double scale, RandomStream stream = RandomStream(0))
      : scale_(scale), stream_(stream) {
    if (!(scale > 0.0 && scale <= 1.0)) {
      throw InvalidArgumentError(
          "scale", fmt::format("scale: value is {}; rule: must lie in (0, 1]", scale));
    }
  }

  [[nodiscard]] double scale() const noexcept { return scale_; }
  /// Restarts the draws from `stream` (the controller passes its "probe" substream).
  void reseed(const RandomStream& stream) { stream_ = stream; }

  void design(const ProbeContext<N>& context, Vector<N>& probe) {
    const Index d = context.covariance.rows();
    if (draw_.size() != d) {
      draw_.resize(d);
      factor_.emplace(d);
    }
    stream_.fill_normal(draw_);  // drawn even when unused: the stream stays aligned per call
    factor_->compute(context.covariance);
    if (factor_->info() != Eigen::Success) {
      probe.setZero(d);  // P not positive definite: nothing sound to sample
      return;
    }
    probe.noalias() = factor_->matrixL() * draw_;
    probe *= scale_;
    probe = probe.cwiseMax(-context.max_probe).cwiseMin(context.max_probe);
  }

  static constexpr std::string_view json_format = "twincal.thompson_probe";

  /// The stream of the draws ξ (seed and engine state): the probe's only state (the factor and
  /// the draw are rewritten by every design()).
  [[nodiscard]] nlohmann::json save() const {
    return {{"format", json_format}, {"stream", json_state::random_stream_to_json(stream_)}};
  }

  /// @throws InvalidArgumentError naming the field; the probe unchanged.
  void restore(const nlohmann::json& saved) {
    json_state::require_format(saved, json_format);
    stream_ = json_state::read_random_stream(json_state::field(saved, "stream"), "stream");
  }

 private:
  double scale_;
  RandomStream stream_;
  Vector<N> draw_;
  std::optional<Eigen::LLT<SquareMatrix<N>>> factor_;  // constructed at its size on first use
};

}  // namespace twincal
