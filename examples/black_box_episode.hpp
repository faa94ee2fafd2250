#pragma once
// What the black-box examples (black_box_twin.cpp, custom_nonlinearity.cpp) share: each run's
// assembly order and drift as the paper's protocol draws them, and the median they report.
#include <algorithm>
#include <cstddef>
#include <vector>

#include "twincal/core/random_stream.hpp"
#include "twincal/models/assembly_id.hpp"
#include "twincal/models/bouncing_drift.hpp"

namespace twincal::examples {

/// The median of `values` (the mean of the middle two for an even count).
inline double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

/// The twin's assemblies in the order of run `run`: shuffled from its substream "order".
template <typename T>
std::vector<AssemblyId> shuffled_assemblies(const T& twin, const RandomStream& run) {
  std::vector<AssemblyId> order = twin.assemblies();
  RandomStream shuffle = run.substream("order");
  for (std::size_t i = order.size() - 1; i > 0; --i) {
    const auto j = static_cast<std::size_t>(shuffle.uniform() * static_cast<double>(i + 1));
    std::swap(order[i], order[std::min(j, i)]);
  }
  return order;
}

/// The bouncing drift of eq. (15) on every locator of `twin` for run `run` (its substream
/// "drift").
template <typename T>
BouncingDrift<Dynamic> run_drift(const T& twin, const RandomStream& run) {
  RandomStream drift_stream = run.substream("drift");
  return BouncingDrift<Dynamic>::random(twin.control_dimension(), drift_stream);
}

/// One episode of run `run` in the paper's protocol: the twin's assemblies in shuffled order,
/// each after one step of the drift; `step(x, offset)` handles assembly x with the plant's
/// offset δu*. Returns whether the run lost the offset: over the second half, its estimates
/// (`estimate()`) were further from δu* than no estimate at all.
template <typename T, typename Step, typename Estimate>
bool drifting_episode(const T& twin, const RandomStream& run, Step step, Estimate estimate) {
  const std::vector<AssemblyId> order = shuffled_assemblies(twin, run);
  BouncingDrift<Dynamic> drift = run_drift(twin, run);
  double error = 0.0;
  double offset = 0.0;
  for (std::size_t t = 0; t < order.size(); ++t) {
    drift.advance();
    step(order[t], drift.offset());
    if (2 * t >= order.size()) {
      error += (estimate() - drift.offset()).norm();
      offset += drift.offset().norm();
    }
  }
  return error > offset;
}

}  // namespace twincal::examples
