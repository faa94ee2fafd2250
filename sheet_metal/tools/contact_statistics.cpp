// Measures the contact cases (docs/sheet_metal.md, "Contact"): how often the flange contacts are
// closed at u = 0, at the searched optimum u0 and at the corners of the locator box, the
// quadratic departure of Q² around u0 (models/quadratic_departure.hpp), and the cost of one
// evaluation.
// Usage: twincal_contact_statistics body|door [nominal_gap_mm] [twin_seed]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string_view>
#include <vector>

#include "twincal/controllers/individual_optimum.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/models/quadratic_departure.hpp"
#include "twincal/sheet_metal/contact_sheet_metal_twin.hpp"

namespace {

using twincal::AssemblyId;
using twincal::ContactSheetMetalTwin;
using twincal::Index;
using twincal::MatrixX;
using twincal::RandomStream;
using twincal::VectorX;

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

Index closed_at(const ContactSheetMetalTwin& twin, const AssemblyId& x, const VectorX& u) {
  return twin.contact_state(x, u).summary.closed;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string_view which = argc >= 2 ? argv[1] : "";
  if (which != "body" && which != "door") {
    std::fprintf(stderr, "usage: twincal_contact_statistics body|door [nominal_gap_mm] [seed]\n");
    return 2;
  }
  const twincal::SheetMetalCase kind =
      which == "body" ? twincal::SheetMetalCase::body : twincal::SheetMetalCase::door;
  twincal::ContactSheetMetalTwinOptions options;
  if (argc >= 3) options.nominal_gap = std::atof(argv[2]);
  const std::uint64_t seed = argc >= 4 ? std::strtoull(argv[3], nullptr, 10) : 2023;

  auto start = std::chrono::steady_clock::now();
  twincal::SheetMetalTwin linear = twincal::SheetMetalTwin::make(kind, seed);
  const double linear_seconds = seconds_since(start);
  start = std::chrono::steady_clock::now();
  const ContactSheetMetalTwin twin(linear, options);
  const double contact_seconds = seconds_since(start);
  const Index d = twin.control_dimension();
  const Index p = twin.pair_count();
  std::printf("case %s, seed %llu, nominal gap %g mm: d = %ld, p = %ld contact pairs, m = %ld\n",
              std::string(which).c_str(), static_cast<unsigned long long>(seed),
              options.nominal_gap, static_cast<long>(d), static_cast<long>(p),
              static_cast<long>(twin.key_response().rows()));
  std::printf("build: linear twin %.3f s, contact model %.3f s\n", linear_seconds, contact_seconds);

  // Cost and contact counts over random controls in the box (one batch per assembly).
  RandomStream stream(11);
  const Index samples = 1000;
  MatrixX controls(d, samples);
  for (double& v : controls.reshaped()) v = 2.0 * stream.uniform() - 1.0;
  VectorX out(samples);
  start = std::chrono::steady_clock::now();
  twin.quality_batch({0, 0}, controls, out);
  const double per_evaluation = seconds_since(start) / static_cast<double>(samples);
  VectorX linear_out(samples);
  twin.linear().quality_batch({0, 0}, controls, linear_out);
  const double change = ((out - linear_out).array().abs() / linear_out.array()).mean();
  double closed_random = 0.0;
  double iterations = 0.0;
  double residual = 0.0;
  Index most_closed = 0;
  for (Index j = 0; j < samples; ++j) {
    const twincal::SheetMetalContactState state = twin.contact_state({0, 0}, controls.col(j));
    closed_random += static_cast<double>(state.summary.closed);
    iterations += static_cast<double>(state.summary.iterations);
    residual = std::max(residual, state.summary.residual);
    most_closed = std::max(most_closed, state.summary.closed);
  }
  std::printf(
      "random u in the box, assembly (0, 0): %.1f us per evaluation, closed %.1f of %ld on "
      "average (max %ld), %.1f solves, max residual %.2g mm; mean |Q - Q_linear| / Q_linear "
      "%.4f\n",
      per_evaluation * 1e6, closed_random / samples, static_cast<long>(p),
      static_cast<long>(most_closed), iterations / samples, residual, change);

  // Closed contacts at u = 0 over all assemblies.
  const std::vector<AssemblyId> all = twin.assemblies();
  double closed_nominal = 0.0;
  Index assemblies_touching = 0;
  for (const AssemblyId& x : all) {
    const Index closed = closed_at(twin, x, VectorX::Zero(d));
    closed_nominal += static_cast<double>(closed);
    assemblies_touching += closed > 0 ? 1 : 0;
  }
  std::printf("u = 0: closed %.2f of %ld on average; %ld of %zu assemblies have a contact\n",
              closed_nominal / static_cast<double>(all.size()), static_cast<long>(p),
              static_cast<long>(assemblies_touching), all.size());

  // The first ten assemblies: u0 searched (NLopt from the linear optimum), contacts at u0 and at
  // random box corners, departure at u0 and at the linear optimum.
  const twincal::IndividualOptimum<ContactSheetMetalTwin> search(twin);
  std::vector<double> departure_u0;
  std::vector<double> departure_linear;
  std::vector<double> closed_u0;
  std::vector<double> closed_corners;
  std::vector<double> corners_touching;
  std::printf(
      "| assembly | Q(u_lin) | z* searched | closed at u0 | departure at u0 | at u_lin |"
      " closed at corners (mean, share with any) | evaluations |\n");
  for (std::size_t a = 0; a < 10; ++a) {
    const AssemblyId x = all[a];
    const VectorX start_point = twin.search_start(x);
    const twincal::IndividualControl found = search.optimize(x, start_point);
    const Index closed = closed_at(twin, x, found.control);
    closed_u0.push_back(static_cast<double>(closed));
    departure_u0.push_back(
        twincal::quadratic_departure(twin, x, found.control, RandomStream(seed).substream(a)));
    departure_linear.push_back(
        twincal::quadratic_departure(twin, x, start_point, RandomStream(seed).substream(a)));
    RandomStream corners = RandomStream(seed).substream("corners").substream(a);
    double closed_sum = 0.0;
    Index touching = 0;
    const Index corner_count = 256;
    for (Index c = 0; c < corner_count; ++c) {
      VectorX corner(d);
      for (Index k = 0; k < d; ++k) corner(k) = corners.uniform() < 0.5 ? -1.0 : 1.0;
      const Index n = closed_at(twin, x, corner);
      closed_sum += static_cast<double>(n);
      touching += n > 0 ? 1 : 0;
    }
    closed_corners.push_back(closed_sum / corner_count);
    corners_touching.push_back(static_cast<double>(touching) / corner_count);
    std::printf("| (%ld, %ld) | %.4f | %.4f | %ld | %.3f | %.3f | %.1f, %.2f | %llu |\n",
                static_cast<long>(x.upper), static_cast<long>(x.lower),
                twin.quality(x, start_point), found.quality, static_cast<long>(closed),
                departure_u0.back(), departure_linear.back(), closed_corners.back(),
                corners_touching.back(), static_cast<unsigned long long>(found.evaluations));
  }
  std::printf(
      "median over the first 10 assemblies: departure %.3f at u0, %.3f at the linear optimum; "
      "closed %.1f of %ld at u0, %.1f at box corners (%.0f%% of corners with a contact)\n",
      median(departure_u0), median(departure_linear), median(closed_u0), static_cast<long>(p),
      median(closed_corners), 100.0 * median(corners_touching));
  return 0;
}
