#pragma once
/// @file
/// `ExternalCaseTwin`: the `external` twin case (external_twin_settings.hpp) as a twin over
/// AssemblyId with a known optimum, so that every controller and the whole episode protocol run
/// on a program's twin as on the built-in ones. Qualities go through an ExternalTwinPool (a batch
/// spread over the workers, failures retried once); u0(x) and z*(x) of every assembly are
/// searched once, at construction, with NLopt from the centre of the bounds — one assembly per
/// worker at a time, so N workers search N assemblies at once — or, with a budget, from a start
/// (the additive warm start, or a fast start twin's own optimum: optimum_start_command).
///
/// Scanned assemblies. Besides its upper_parts × lower_parts pairs, the twin takes assemblies
/// given by their scanned parts (any JSON, e.g. a cell's measurements): add_scanned() registers
/// one, searches its optimum and returns its id, scanned_assembly(k) for the k-th registered
/// (scanned_assembly.hpp); the program then receives {"parts": <the parts>} as the assembly.

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "twincal/core/eigen.hpp"
#include "twincal/experiments/external_twin_settings.hpp"
#include "twincal/experiments/scanned_assembly.hpp"
#include "twincal/experiments/searched_optima_file.hpp"
#include "twincal/external/external_twin_backend.hpp"
#include "twincal/external/external_twin_pool.hpp"
#include "twincal/models/assembly_id.hpp"
#include "twincal/models/twin.hpp"

namespace twincal {

/// The ExternalTwinPool options of `settings`: its command, locators, bounds, time limits and
/// workers. @throws InvalidArgumentError for invalid settings.
[[nodiscard]] ExternalTwinPoolOptions external_twin_pool_options(
    const ExternalTwinSettings& settings);

/// Makes where an external twin's evaluations run, from its settings (MpiTwinPool,
/// apps/distributed, is one). An empty factory means an ExternalTwinPool of settings.workers
/// processes on this machine.
using ExternalTwinBackendFactory =
    std::function<std::unique_ptr<ExternalTwinBackend>(const ExternalTwinSettings&)>;

class ExternalCaseTwin {
 public:
  using Assembly = AssemblyId;

  /// Starts the workers (the backend that `backend` makes, by default an ExternalTwinPool) and
  /// searches every assembly's optimum, or reads those settings.optima_file holds and searches
  /// the others, rewriting the file after each.
  /// @throws InvalidArgumentError for invalid settings, an optima_file that does not serve them
  ///         or cannot be written (checked before the search); ExternalTwinError when the
  ///         program fails (after the pool's retry), naming the assembly whose search failed.
  explicit ExternalCaseTwin(const ExternalTwinSettings& settings,
                            const ExternalTwinBackendFactory& backend = {});

  [[nodiscard]] Index control_dimension() const { return backend_->control_dimension(); }
  [[nodiscard]] const std::vector<std::string>& locator_names() const {
    return backend_->locator_names();
  }
  [[nodiscard]] const VectorX& lower_bounds() const { return backend_->lower_bounds(); }
  [[nodiscard]] const VectorX& upper_bounds() const { return backend_->upper_bounds(); }
  [[nodiscard]] double quality(const AssemblyId& assembly,
                               const Eigen::Ref<const VectorX>& control) const {
    double q = 0.0;
    backend_->quality_batch(assembly_json(assembly), control, Eigen::Map<VectorX>(&q, 1));
    return q;
  }
  void quality_batch(const AssemblyId& assembly, const Eigen::Ref<const MatrixX>& controls,
                     Eigen::Ref<VectorX> out) const {
    backend_->quality_batch(assembly_json(assembly), controls, out);
  }
  /// m, the key points of deviations_batch (external_twin.key_points; 0: qualities only).
  [[nodiscard]] Index key_point_count() const { return backend_->key_point_count(); }
  /// The key points' deviations of every column of `controls` (m × k), through the backend.
  /// @throws InvalidArgumentError when key_points is 0; as quality_batch otherwise.
  void deviations_batch(const AssemblyId& assembly, const Eigen::Ref<const MatrixX>& controls,
                        Eigen::Ref<MatrixX> out) const {
    backend_->deviations_batch(assembly_json(assembly), controls, out);
  }
  /// u0(x) as searched at construction (or by add_scanned()).
  [[nodiscard]] VectorX optimum(const AssemblyId& assembly) const {
    return optima_.col(position(assembly));
  }
  [[nodiscard]] double optimal_quality(const AssemblyId& assembly) const {
    return optimal_qualities_(position(assembly));
  }
  /// Registers the assembly of scanned `parts` and searches its optimum (from the start twin's,
  /// which registers them too, where there is one), or takes
  /// `known` (what an earlier search found, e.g. from a history) without a search; parts equal
  /// (as JSON) to registered ones give their id again. Not for use concurrent with other calls.
  /// @throws ExternalTwinError when the program fails (after the pool's retry);
  ///         DimensionMismatchError, NonFiniteError for a bad `known`; nothing is registered then.
  AssemblyId add_scanned(const nlohmann::json& parts,
                         const std::optional<ScannedOptimum>& known = std::nullopt);
  /// Scanned assemblies registered so far.
  [[nodiscard]] Index scanned_count() const noexcept { return std::ssize(scanned_parts_); }
  /// Every (upper, lower) pair, upper-major (the scanned assemblies are not listed).
  [[nodiscard]] const std::vector<AssemblyId>& assemblies() const noexcept { return assemblies_; }
  /// Whether every pair's optimum was read from settings.optima_file, none searched (a file of
  /// an interrupted search gives the pairs it holds, and the others are searched).
  [[nodiscard]] bool optima_read() const noexcept { return optima_read_; }
  /// Evaluations the optimum searches took, over all assemblies (for optima read from a file,
  /// what the search that wrote it took).
  [[nodiscard]] std::uint64_t search_evaluations() const noexcept {
    return search_cost_.evaluations;
  }
  /// Requests the optimum searches made: one per evaluation for BOBYQA, one per batch (round of
  /// the twin's latency) for the trust region and least squares.
  [[nodiscard]] std::uint64_t search_requests() const noexcept { return search_cost_.requests; }
  /// Evaluations of the start twin (external_twin.optimum_start_command) in the full searches
  /// of the optima that started this twin's searches; 0 without one.
  [[nodiscard]] std::uint64_t start_search_evaluations() const noexcept {
    return start_twin_ ? start_twin_->search_evaluations() : 0;
  }
  /// Where the evaluations run (an ExternalTwinPool unless another backend was made).
  [[nodiscard]] const ExternalTwinBackend& backend() const noexcept { return *backend_; }

  /// What the program receives as the assembly: {"upper": i, "lower": j}, or {"parts": …} for
  /// a scanned one. @throws InvalidArgumentError for an unknown assembly.
  [[nodiscard]] nlohmann::json assembly_json(const AssemblyId& assembly) const;

 private:
  // Column of `assembly` in optima_: the pairs first, then the scanned assemblies.
  [[nodiscard]] Index position(const AssemblyId& assembly) const;
  // u0 and z* of `assembly` (as the program receives it), searched with worker `worker` from
  // `start` with NLopt's two phases and these budgets, into `optimum` and `quality`; returns the
  // evaluations it took.
  // The trust region or least squares (optimum_method) runs when the search is budgeted; with
  // `whole_pool` (no other search in flight) its rounds spread over every worker.
  struct SearchCost {
    std::uint64_t evaluations = 0;
    std::uint64_t requests = 0;
    SearchCost& operator+=(const SearchCost& other) noexcept {
      evaluations += other.evaluations;
      requests += other.requests;
      return *this;
    }
  };
  SearchCost search(Index worker, bool whole_pool, const nlohmann::json& assembly,
                    const VectorX& start, Index global_evaluations, Index local_evaluations,
                    Eigen::Ref<VectorX> optimum, double& quality) const;
  // Called with the pairs found so far after each one the search finishes (under a lock).
  using FoundPairs = std::function<void(const SearchedOptima&)>;
  // Searches the optima of the pairs `pairs` has not found into it.
  void search_pairs(SearchedOptima& pairs, const FoundPairs& found);
  // Searches the pairs at `positions` (indices into assemblies_) into `pairs`, one request in
  // flight per worker, each from start(assembly).
  template <typename Start>
  void search_all(const std::vector<Index>& positions, const Start& start, Index global_evaluations,
                  Index local_evaluations, SearchedOptima& pairs, const FoundPairs& found);

  std::unique_ptr<ExternalTwinBackend> backend_;
  // The fast twin whose optima start the budgeted searches (optimum_start_command), or none.
  std::unique_ptr<ExternalCaseTwin> start_twin_;
  Index lower_parts_;
  Index global_evaluations_;
  Index local_evaluations_;
  Index budget_;        // optimum_budget: 0 for the full search
  std::string method_;  // optimum_method: how a budgeted search runs
  std::uint64_t seed_;  // optimum_seed: the least-squares restarts
  std::vector<AssemblyId> assemblies_;
  std::vector<nlohmann::json> scanned_parts_;  // k-th scanned assembly's parts
  std::map<std::string, Index> scanned_ids_;   // parts (compact JSON) → k
  MatrixX optima_;                             // d × (pairs + scanned)
  VectorX optimal_qualities_;                  // pairs + scanned
  SearchCost search_cost_;
  bool optima_read_ = false;
};

static_assert(TwinWithOptimum<ExternalCaseTwin> && TwinWithDeviations<ExternalCaseTwin>);

}  // namespace twincal
