// ExternalCaseTwin (external_case_twin.hpp): the pool and the optimum searches.
#include "twincal/experiments/external_case_twin.hpp"

#include <algorithm>
#include <chrono>
#include <exception>
#include <thread>

#include <fmt/format.h>

#include "twincal/controllers/individual_optimum.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/options.hpp"

namespace twincal {
namespace {

ExternalTwinPoolOptions pool_options(const ExternalTwinSettings& settings) {
  require_valid("external_twin", settings);
  ExternalTwinPoolOptions options;
  options.twin.command = settings.command;
  options.twin.locator_names = settings.locators;
  options.twin.lower_bounds =
      Eigen::Map<const VectorX>(settings.lower_bounds.data(), std::ssize(settings.lower_bounds));
  options.twin.upper_bounds =
      Eigen::Map<const VectorX>(settings.upper_bounds.data(), std::ssize(settings.upper_bounds));
  options.twin.timeout = std::chrono::milliseconds{settings.timeout_ms};
  options.workers = settings.workers;
  return options;
}

}  // namespace

nlohmann::json ExternalCaseTwin::assembly_json(const AssemblyId& assembly) {
  return {{"upper", assembly.upper}, {"lower", assembly.lower}};
}

ExternalCaseTwin::ExternalCaseTwin(const ExternalTwinSettings& settings)
    : pool_(pool_options(settings)), lower_parts_(settings.lower_parts) {
  for (Index i = 0; i < settings.upper_parts; ++i) {
    for (Index j = 0; j < settings.lower_parts; ++j) assemblies_.push_back({i, j});
  }
  const Index n = std::ssize(assemblies_);
  const Index d = control_dimension();
  optima_.resize(d, n);
  optimal_qualities_.resize(n);
  // Worker w searches assemblies w, w + T, …: one request in flight per worker.
  const Index threads = std::min(pool_.workers(), n);
  std::vector<std::exception_ptr> failures(static_cast<std::size_t>(threads));
  std::vector<std::uint64_t> evaluations(static_cast<std::size_t>(threads), 0);
  const VectorX centre = 0.5 * (lower_bounds() + upper_bounds());
  const auto search = [&](Index w) {
    NloptOptimizerOptions budgets;
    budgets.global_evaluations = static_cast<std::uint64_t>(settings.optimum_global_evaluations);
    budgets.local_evaluations = static_cast<std::uint64_t>(settings.optimum_local_evaluations);
    const IndividualOptimum<ExternalTwin> optimum(pool_.worker(w), NloptOptimizer(budgets));
    for (Index a = w; a < n; a += threads) {
      const AssemblyId& x = assemblies_[static_cast<std::size_t>(a)];
      try {
        const IndividualControl found = optimum.optimize(assembly_json(x), centre);
        optima_.col(a) = found.control;
        optimal_qualities_(a) = found.quality;
        evaluations[static_cast<std::size_t>(w)] += found.evaluations;
      } catch (...) {
        failures[static_cast<std::size_t>(w)] = std::current_exception();
        return;
      }
    }
  };
  {
    std::vector<std::jthread> workers;
    for (Index w = 1; w < threads; ++w) workers.emplace_back(search, w);
    search(0);
  }
  for (const std::exception_ptr& failure : failures) {
    if (failure) std::rethrow_exception(failure);
  }
  for (const std::uint64_t e : evaluations) search_evaluations_ += e;
}

Index ExternalCaseTwin::position(const AssemblyId& assembly) const {
  const Index upper_parts = std::ssize(assemblies_) / lower_parts_;
  if (assembly.upper < 0 || assembly.upper >= upper_parts || assembly.lower < 0 ||
      assembly.lower >= lower_parts_) {
    throw InvalidArgumentError(
        "assembly", fmt::format("assembly: {} is unknown; rule: parts within {} × {}", assembly,
                                upper_parts, lower_parts_));
  }
  return assembly.upper * lower_parts_ + assembly.lower;
}

}  // namespace twincal
