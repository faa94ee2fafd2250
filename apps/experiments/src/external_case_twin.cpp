// ExternalCaseTwin (external_case_twin.hpp): the pool and the optimum searches.
#include "twincal/experiments/external_case_twin.hpp"

#include <algorithm>
#include <chrono>
#include <exception>
#include <optional>
#include <thread>

#include <fmt/format.h>

#include "twincal/controllers/individual_optimum.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/options.hpp"
#include "twincal/core/validate.hpp"

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

nlohmann::json ExternalCaseTwin::assembly_json(const AssemblyId& assembly) const {
  if (const std::optional<Index> k = scanned_index(assembly)) {
    (void)position(assembly);  // throws for one not registered
    return {{"parts", scanned_parts_[static_cast<std::size_t>(*k)]}};
  }
  return {{"upper", assembly.upper}, {"lower", assembly.lower}};
}

ExternalCaseTwin::ExternalCaseTwin(const ExternalTwinSettings& settings)
    : pool_(pool_options(settings)),
      lower_parts_(settings.lower_parts),
      global_evaluations_(settings.optimum_global_evaluations),
      local_evaluations_(settings.optimum_local_evaluations) {
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
  const auto search_share = [&](Index w) {
    for (Index a = w; a < n; a += threads) {
      try {
        evaluations[static_cast<std::size_t>(w)] +=
            search(w, assembly_json(assemblies_[static_cast<std::size_t>(a)]), optima_.col(a),
                   optimal_qualities_(a));
      } catch (...) {
        failures[static_cast<std::size_t>(w)] = std::current_exception();
        return;
      }
    }
  };
  {
    std::vector<std::jthread> workers;
    for (Index w = 1; w < threads; ++w) workers.emplace_back(search_share, w);
    search_share(0);
  }
  for (const std::exception_ptr& failure : failures) {
    if (failure) std::rethrow_exception(failure);
  }
  for (const std::uint64_t e : evaluations) search_evaluations_ += e;
}

std::uint64_t ExternalCaseTwin::search(Index worker, const nlohmann::json& assembly,
                                       Eigen::Ref<VectorX> optimum, double& quality) const {
  NloptOptimizerOptions budgets;
  budgets.global_evaluations = static_cast<std::uint64_t>(global_evaluations_);
  budgets.local_evaluations = static_cast<std::uint64_t>(local_evaluations_);
  const IndividualOptimum<ExternalTwin> optimizer(pool_.worker(worker), NloptOptimizer(budgets));
  const VectorX centre = 0.5 * (lower_bounds() + upper_bounds());
  const IndividualControl found = optimizer.optimize(assembly, centre);
  optimum = found.control;
  quality = found.quality;
  return found.evaluations;
}

AssemblyId ExternalCaseTwin::add_scanned(const nlohmann::json& parts,
                                         const std::optional<ScannedOptimum>& known) {
  const std::string key = parts.dump();
  if (const auto found = scanned_ids_.find(key); found != scanned_ids_.end()) {
    return scanned_assembly(found->second);
  }
  VectorX optimum(control_dimension());
  double quality = 0.0;
  std::uint64_t evaluations = 0;
  if (known) {
    require_dimension("known.control", known->control.size(), control_dimension());
    require_finite("known.control", known->control);
    require_finite("known.quality", known->quality);
    optimum = known->control;
    quality = known->quality;
  } else {
    evaluations = search(0, {{"parts", parts}}, optimum, quality);
  }
  // The search succeeded: only now does anything change.
  const Index column = optima_.cols();
  optima_.conservativeResize(Eigen::NoChange, column + 1);
  optima_.col(column) = optimum;
  optimal_qualities_.conservativeResize(column + 1);
  optimal_qualities_(column) = quality;
  const Index k = scanned_count();
  scanned_parts_.push_back(parts);
  scanned_ids_.emplace(key, k);
  search_evaluations_ += evaluations;
  return scanned_assembly(k);
}

Index ExternalCaseTwin::position(const AssemblyId& assembly) const {
  const Index pairs = std::ssize(assemblies_);
  if (const std::optional<Index> k = scanned_index(assembly)) {
    if (*k >= scanned_count()) {
      throw InvalidArgumentError(
          "assembly", fmt::format("assembly: scanned assembly {} is unknown; rule: {} scanned "
                                  "assemblies are registered",
                                  *k, scanned_count()));
    }
    return pairs + *k;
  }
  const Index upper_parts = pairs / lower_parts_;
  if (assembly.upper < 0 || assembly.upper >= upper_parts || assembly.lower < 0 ||
      assembly.lower >= lower_parts_) {
    throw InvalidArgumentError(
        "assembly", fmt::format("assembly: {} is unknown; rule: parts within {} × {}", assembly,
                                upper_parts, lower_parts_));
  }
  return assembly.upper * lower_parts_ + assembly.lower;
}

}  // namespace twincal
