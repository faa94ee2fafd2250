#pragma once
// Test support: replaying filterpy's reference runs (tests/data/filter_runs_*.json) through a
// twincal filter. Each run is a random walk (RandomWalk, Q = Σu·I) observed through
// z = √(q0 + eᵀHe), e = u − x − a (QuadraticQualityMeasurement); per step the filter predicts,
// then updates with (z; a, u), and every stored quantity is compared.

#include <iostream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "golden.hpp"
#include "twincal/filters/julier_sigma_points.hpp"
#include "twincal/filters/merwe_scaled_sigma_points.hpp"
#include "twincal/filters/quadratic_quality_measurement.hpp"
#include "twincal/filters/sigma_point_filter_options.hpp"
#include "twincal/filters/spherical_radial_sigma_points.hpp"
#include "twincal/models/random_walk.hpp"

namespace twincal::test_support {

template <int N>
RandomWalk<N> process_model(const nlohmann::json& run) {
  return RandomWalk<N>::isotropic(run["d"].get<Index>(), run["Sigma_u"].get<double>());
}

template <int N>
QuadraticQualityMeasurement<N> measurement_model(const nlohmann::json& run) {
  return QuadraticQualityMeasurement<N>(matrix<N, N>(run["H"]), run["q0"].get<double>(),
                                        run["sigma_z2"].get<double>());
}

/// The sigma-point policy of a stored file: filterpy 1.4.5's UKF reuses the propagated points,
/// master's redraws them; both versions' CKF reuses them.
inline SigmaPointRefresh refresh_of(const std::string& file, const nlohmann::json& run) {
  if (run["filter"] == "ckf") return SigmaPointRefresh::reuse_propagated;
  return file == "filter_runs_1.4.5.json" ? SigmaPointRefresh::reuse_propagated
                                          : SigmaPointRefresh::redraw;
}

/// Calls `visit(scheme)` with the run's scheme object.
template <typename Visitor>
void with_scheme(const nlohmann::json& run, Visitor&& visit) {
  if (run["filter"] == "ckf") {
    visit(SphericalRadialSigmaPoints{});
    return;
  }
  const nlohmann::json& points = run["points"];
  if (points["scheme"] == "merwe") {
    visit(MerweScaledSigmaPoints{points["alpha"].get<double>(), points["beta"].get<double>(),
                                 points["kappa"].get<double>()});
  } else if (points["scheme"] == "julier") {
    visit(JulierSigmaPoints{points["kappa"].get<double>()});
  } else {
    ADD_FAILURE() << "unknown scheme " << points.dump();
  }
}

/// Runs `filter` over every step of `run`, recording the agreement of each stored quantity.
template <typename Filter>
Agreement replay(Filter& filter, const nlohmann::json& run) {
  constexpr int N = Filter::dimension_at_compile_time;
  Agreement agreement;
  const nlohmann::json& inputs = run["inputs"];
  const nlohmann::json& steps = run["steps"];
  for (std::size_t t = 0; t < steps.size(); ++t) {
    const nlohmann::json& step = steps[t];
    filter.predict();
    agreement.add("x_prior", filter.state(), vector<N>(step["x_prior"]));
    agreement.add("P_prior", filter.covariance(), matrix<N, N>(step["P_prior"]));
    const typename Filter::Inputs in{vector<N>(inputs[t]["a"]), vector<N>(inputs[t]["u"])};
    filter.update(inputs[t]["z"].get<double>(), in);
    agreement.add("x", filter.state(), vector<N>(step["x"]));
    agreement.add("P", filter.covariance(), matrix<N, N>(step["P"]));
    agreement.add("K", filter.last_update().gain, vector<N>(step["K"]));
    agreement.add("S", filter.last_update().innovation_variance, step["S"].get<double>());
    agreement.add("y", filter.last_update().innovation, step["y"].get<double>());
    if (step.contains("log_likelihood")) {
      agreement.add("log_likelihood", filter.last_update().log_likelihood(),
                    step["log_likelihood"].get<double>());
    }
  }
  return agreement;
}

/// A readable name of a run: "ukf merwe(0.1, 2, 0) d=3".
inline std::string describe(const std::string& file, const nlohmann::json& run) {
  std::string name = file + ": " + run["filter"].get<std::string>();
  if (run.contains("points") && !run["points"].is_null()) name += " " + run["points"].dump();
  return name + " d=" + std::to_string(run["d"].get<int>());
}

}  // namespace twincal::test_support
