// ExternalCaseTwin (external_case_twin.hpp): the pool and the optimum searches.
#include "twincal/experiments/external_case_twin.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <mutex>
#include <optional>
#include <thread>

#include <fmt/format.h>

#include "twincal/controllers/additive_warm_start.hpp"
#include "twincal/controllers/least_squares_search.hpp"
#include "twincal/controllers/nlopt_optimizer.hpp"
#include "twincal/controllers/trust_region_search.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/options.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/core/validate.hpp"
#include "twincal/experiments/searched_optima_file.hpp"

namespace twincal {

ExternalTwinPoolOptions external_twin_pool_options(const ExternalTwinSettings& settings) {
  require_valid("external_twin", settings);
  ExternalTwinPoolOptions options;
  options.twin.command = settings.command;
  options.twin.locator_names = settings.locators;
  options.twin.lower_bounds =
      Eigen::Map<const VectorX>(settings.lower_bounds.data(), std::ssize(settings.lower_bounds));
  options.twin.upper_bounds =
      Eigen::Map<const VectorX>(settings.upper_bounds.data(), std::ssize(settings.upper_bounds));
  options.twin.timeout = std::chrono::milliseconds{settings.timeout_ms};
  options.twin.startup_grace = std::chrono::milliseconds{settings.startup_grace_ms};
  options.twin.key_points = settings.key_points;
  options.workers = settings.workers;
  return options;
}

namespace {

std::unique_ptr<ExternalTwinBackend> make_backend(const ExternalTwinSettings& settings,
                                                  const ExternalTwinBackendFactory& factory) {
  if (!factory) return std::make_unique<ExternalTwinPool>(external_twin_pool_options(settings));
  require_valid("external_twin", settings);
  std::unique_ptr<ExternalTwinBackend> backend = factory(settings);
  if (!backend) {
    throw InvalidArgumentError("backend", "backend: the factory made none; rule: it must make one");
  }
  return backend;
}

// The start twin of `settings` (optimum_start_command, whose doc says why one process): the
// same assemblies, locators and bounds, searched in full; null without one. `settings` were
// validated by make_backend().
std::unique_ptr<ExternalCaseTwin> make_start_twin(const ExternalTwinSettings& settings) {
  if (settings.optimum_start_command.empty()) return nullptr;
  ExternalTwinSettings start = settings;
  start.command = settings.optimum_start_command;
  start.workers = 1;
  start.optimum_start_command.clear();
  start.optimum_budget = 0;
  start.optimum_method = "bobyqa";
  start.key_points = 0;
  start.optima_file.clear();
  return std::make_unique<ExternalCaseTwin>(start);
}

}  // namespace

nlohmann::json ExternalCaseTwin::assembly_json(const AssemblyId& assembly) const {
  if (const std::optional<Index> k = scanned_index(assembly)) {
    (void)position(assembly);  // throws for one not registered
    return {{"parts", scanned_parts_[static_cast<std::size_t>(*k)]}};
  }
  return {{"upper", assembly.upper}, {"lower", assembly.lower}};
}

ExternalCaseTwin::ExternalCaseTwin(const ExternalTwinSettings& settings,
                                   const ExternalTwinBackendFactory& backend)
    : backend_(make_backend(settings, backend)),
      start_twin_(make_start_twin(settings)),
      lower_parts_(settings.lower_parts),
      global_evaluations_(settings.optimum_global_evaluations),
      local_evaluations_(settings.optimum_local_evaluations),
      budget_(settings.optimum_budget),
      method_(settings.optimum_method),
      seed_(settings.optimum_seed) {
  for (Index i = 0; i < settings.upper_parts; ++i) {
    for (Index j = 0; j < settings.lower_parts; ++j) assemblies_.push_back({i, j});
  }
  // A program that answers another number of deviations than key_points says would fail every
  // model fitted from them, and the active controller would run on its fallback without a word
  // in the results: one request at the first assembly and the box's centre refuses it here,
  // naming the rule (ExternalTwinError, "… has 50 deviations; rule: must have 60 …").
  if (key_point_count() > 0 && !assemblies_.empty()) {
    const MatrixX centre = 0.5 * (lower_bounds() + upper_bounds());
    MatrixX deviations(key_point_count(), 1);
    deviations_batch(assemblies_.front(), centre, deviations);
  }
  SearchedOptima pairs(control_dimension(), std::ssize(assemblies_));
  const std::string& file = settings.optima_file;
  if (!file.empty()) {
    if (std::optional<SearchedOptima> kept = read_searched_optima(file, settings)) {
      pairs = std::move(*kept);
    } else {
      require_writable_optima_file(file);  // before the search, not after it
    }
  }
  optima_read_ = pairs.complete();
  if (!optima_read_) {
    // After each pair the file holds every pair found so far, so a killed study resumes there.
    search_pairs(
        pairs, file.empty() ? FoundPairs{} : [&](const SearchedOptima& found) {
          write_searched_optima(file, settings, found);
        });
  }
  optima_ = std::move(pairs.controls);
  optimal_qualities_ = std::move(pairs.qualities);
  search_cost_ = {pairs.evaluations, pairs.requests};
}

void ExternalCaseTwin::search_pairs(SearchedOptima& pairs, const FoundPairs& found) {
  const Index n = std::ssize(assemblies_);
  const VectorX centre = 0.5 * (lower_bounds() + upper_bounds());
  const auto from_centre = [&](const AssemblyId&) { return centre; };
  // The pairs of `phase` (0 or 1 for the budgeted search's phases, −1: all) not yet found.
  const auto missing = [&](int phase) {
    std::vector<Index> positions;
    for (Index a = 0; a < n; ++a) {
      const AssemblyId& assembly = assemblies_[static_cast<std::size_t>(a)];
      if ((phase < 0 || AdditiveWarmStart::phase(assembly) == phase) &&
          !pairs.found[static_cast<std::size_t>(a)]) {
        positions.push_back(a);
      }
    }
    return positions;
  };
  if (budget_ == 0) {
    search_all(missing(-1), from_centre, global_evaluations_, local_evaluations_, pairs, found);
    return;
  }
  if (start_twin_) {
    search_all(
        missing(-1), [&](const AssemblyId& assembly) { return start_twin_->optimum(assembly); }, 0,
        budget_, pairs, found);
    return;
  }
  // Budgeted: the first row and column from the centre, then the others from the additive warm
  // start, each phase finished before the next, so no start depends on the workers' timing.
  search_all(missing(0), from_centre, 0, 2 * budget_, pairs, found);
  AdditiveWarmStart warm(lower_bounds(), upper_bounds());
  for (Index a = 0; a < n; ++a) {
    const AssemblyId& assembly = assemblies_[static_cast<std::size_t>(a)];
    if (AdditiveWarmStart::phase(assembly) == 0) warm.record(assembly, pairs.controls.col(a));
  }
  search_all(
      missing(1), [&](const AssemblyId& assembly) { return warm.start(assembly, centre); }, 0,
      budget_, pairs, found);
}

template <typename Start>
void ExternalCaseTwin::search_all(const std::vector<Index>& positions, const Start& start,
                                  Index global_evaluations, Index local_evaluations,
                                  SearchedOptima& pairs, const FoundPairs& found) {
  const Index count = std::ssize(positions);
  if (count == 0) return;
  // Worker w searches positions w, w + T, …: one request in flight per worker. Each result joins
  // `pairs` (and `found` sees them) under one lock, so no worker reads a column another writes.
  const Index threads = std::min(backend_->workers(), count);
  std::vector<std::exception_ptr> failures(static_cast<std::size_t>(threads));
  std::mutex joining;
  const auto search_share = [&](Index w) {
    VectorX optimum(control_dimension());
    double quality = 0.0;
    for (Index k = w; k < count; k += threads) {
      const Index a = positions[static_cast<std::size_t>(k)];
      const AssemblyId& assembly = assemblies_[static_cast<std::size_t>(a)];
      try {
        const SearchCost cost = search(w, threads == 1, assembly_json(assembly), start(assembly),
                                       global_evaluations, local_evaluations, optimum, quality);
        const std::lock_guard lock(joining);
        pairs.controls.col(a) = optimum;
        pairs.qualities(a) = quality;
        pairs.found[static_cast<std::size_t>(a)] = true;
        pairs.evaluations += cost.evaluations;
        pairs.requests += cost.requests;
        if (found) found(pairs);
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
}

ExternalCaseTwin::SearchCost ExternalCaseTwin::search(
    Index worker, bool whole_pool, const nlohmann::json& assembly, const VectorX& start,
    Index global_evaluations, Index local_evaluations, Eigen::Ref<VectorX> optimum,
    double& quality) const {
  const ExternalTwinBackend& twin = *backend_;
  // A batched search (trust region, least squares) to its summary's cost; its start without a
  // quality means the twin cannot evaluate this assembly's centre.
  const auto batched = [&](const auto& minimize) -> SearchCost {
    try {
      const auto found = minimize();
      optimum = found.argmin;
      quality = found.minimum;
      return {found.evaluations, static_cast<std::uint64_t>(found.batches)};
    } catch (const NonFiniteError& error) {
      throw InvalidArgumentError(
          "optimum", fmt::format("optimum: the twin answered no quality for assembly {} ({}); "
                                 "rule: the u0 search needs evaluable controls",
                                 assembly.dump(), error.what()));
    }
  };
  // A round's controls spread over the pool when this is the only search (a scanned assembly, a
  // phase of one), else one request to this worker.
  if (budget_ > 0 && method_ == "trust_region") {
    const BatchObjective objective = [&](const Eigen::Ref<const MatrixX>& controls,
                                         Eigen::Ref<VectorX> qualities) {
      if (whole_pool) {
        twin.quality_batch(assembly, controls, qualities);
      } else {
        twin.worker_quality_batch(worker, assembly, controls, qualities);
      }
    };
    const TrustRegionSearch search(
        TrustRegionSearchOptions{.evaluations = static_cast<std::uint64_t>(local_evaluations)});
    return batched(
        [&] { return search.minimize(objective, start, lower_bounds(), upper_bounds()); });
  }
  if (budget_ > 0 && least_squares_method(method_)) {
    const DeviationObjective objective = [&](const Eigen::Ref<const MatrixX>& controls,
                                             Eigen::Ref<MatrixX> deviations) {
      if (whole_pool) {
        twin.deviations_batch(assembly, controls, deviations);
      } else {
        twin.worker_deviations_batch(worker, assembly, controls, deviations);
      }
    };
    const LeastSquaresSearch search(
        least_squares_options(method_, static_cast<std::uint64_t>(local_evaluations)));
    return batched([&] {
      return search.minimize(objective, twin.key_point_count(), start, lower_bounds(),
                             upper_bounds(), RandomStream(seed_).substream(assembly.dump()));
    });
  }
  NloptOptimizerOptions budgets;
  budgets.global_evaluations = static_cast<std::uint64_t>(global_evaluations);
  budgets.local_evaluations = static_cast<std::uint64_t>(local_evaluations);
  // A control the program cannot evaluate (it answers null: a solver that did not converge)
  // counts, for the search only, as worse than anything seen: 2 × the largest quality so far
  // + 1 mm. The optimum is the best control the program did evaluate.
  double largest = 0.0;
  double best = std::numeric_limits<double>::infinity();
  VectorX best_control = start;
  std::uint64_t unevaluable = 0;
  const Objective objective = [&](const Eigen::Ref<const VectorX>& u) {
    double q = 0.0;
    twin.worker_quality_batch(worker, assembly, u, Eigen::Map<VectorX>(&q, 1));
    if (!std::isfinite(q)) {
      ++unevaluable;
      return 2.0 * largest + 1.0;
    }
    largest = std::max(largest, q);
    if (q < best) {
      best = q;
      best_control = u;
    }
    return q;
  };
  const OptimizationResult found =
      NloptOptimizer(budgets).minimize(objective, start, lower_bounds(), upper_bounds());
  if (!std::isfinite(best)) {
    throw InvalidArgumentError(
        "optimum",
        fmt::format("optimum: the twin answered no quality at any of the {} controls searched "
                    "for assembly {}; rule: the u0 search needs evaluable controls",
                    found.evaluations, assembly.dump()));
  }
  optimum = best_control;
  quality = best;
  return {found.evaluations, found.evaluations};
}

AssemblyId ExternalCaseTwin::add_scanned(const nlohmann::json& parts,
                                         const std::optional<ScannedOptimum>& known) {
  const std::string key = parts.dump();
  if (const auto found = scanned_ids_.find(key); found != scanned_ids_.end()) {
    return scanned_assembly(found->second);
  }
  VectorX optimum(control_dimension());
  double quality = 0.0;
  SearchCost cost;
  if (known) {
    require_dimension("known.control", known->control.size(), control_dimension());
    require_finite("known.control", known->control);
    require_finite("known.quality", known->quality);
    optimum = known->control;
    quality = known->quality;
  } else if (start_twin_) {
    const VectorX start = start_twin_->optimum(start_twin_->add_scanned(parts));
    cost = search(0, true, {{"parts", parts}}, start, 0, budget_, optimum, quality);
  } else {
    const VectorX centre = 0.5 * (lower_bounds() + upper_bounds());
    cost = budget_ == 0
               ? search(0, true, {{"parts", parts}}, centre, global_evaluations_,
                        local_evaluations_, optimum, quality)
               : search(0, true, {{"parts", parts}}, centre, 0, 2 * budget_, optimum, quality);
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
  search_cost_ += cost;
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
