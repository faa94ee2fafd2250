#pragma once
/// @file
/// `Evaluator<T, E>`: the layer between filters/controllers and a black-box twin.
///
/// An Evaluator is itself a Twin (so QualityFeedback<Evaluator<T>> works unchanged) that adds to
/// every `quality_batch` call:
/// - execution: serially or spread over a thread pool (ParallelExecution), results in input
///   order;
/// - accounting: one EvaluationCounter record per call (the twin evaluations it caused and its
///   wall time), readable with stats();
/// - failure checks: a twin that throws, a NaN/±∞ quality, or a twin call slower than
///   `options.time_limit` becomes a TwinEvaluationError carrying the assembly and the controls
///   of the failing twin call (the twin's own exception nested); nothing is dropped or patched;
/// - optional memoization of repeated (assembly, u) pairs (exact, bitwise match of u).
/// A twin that answers its key points' deviations (TwinWithDeviations) has them passed on by
/// `deviations_batch` the same way — executed, counted, checked — but never memoized.
///
/// The time limit of an in-process twin is checked when the call returns (a thread cannot be
/// pre-empted safely), so it reports a slow twin rather than bounding the wait; ExternalTwin
/// enforces its own timeout by killing the child. When a call fails, `out` is left partly
/// written (basic guarantee) and the cache keeps only values that passed the checks.
/// The evaluator refers to the twin, which must outlive it.

#include <atomic>
#include <chrono>
#include <cmath>
#include <concepts>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <exception>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/evaluation_counter.hpp"
#include "twincal/core/options.hpp"
#include "twincal/core/stopwatch.hpp"
#include "twincal/models/evaluation_error.hpp"
#include "twincal/models/execution.hpp"
#include "twincal/models/kept_assemblies.hpp"
#include "twincal/models/twin.hpp"

namespace twincal {

struct EvaluatorOptions {
  /// Longest acceptable duration of one twin call (a batch or a range of one); none by default.
  std::optional<std::chrono::nanoseconds> time_limit = std::nullopt;
  /// Remember Q(x, u) and answer repeated pairs without calling the twin. Needs std::hash and
  /// == for the twin's Assembly.
  bool memoize = false;

  [[nodiscard]] std::optional<std::string> validate() const {
    return rule::check(!time_limit || time_limit->count() > 0, "time_limit",
                       time_limit.value_or(std::chrono::nanoseconds{0}).count(),
                       "must be > 0 (ns)");
  }
};

/// An assembly type usable as a memoization key.
template <typename A>
concept HashableAssembly = std::copy_constructible<A> && std::equality_comparable<A> &&
    requires(const A& a) {
  { std::hash<A>{}(a) } -> std::convertible_to<std::size_t>;
};

template <Twin T, Execution E = SerialExecution>
class Evaluator {
 public:
  using Assembly = typename T::Assembly;
  static constexpr bool borrows_assemblies = borrows_assemblies_v<T>;

  /// @throws InvalidArgumentError when the options are invalid or ask for memoization of an
  ///         assembly type without std::hash / ==.
  explicit Evaluator(const T& twin, E execution = E{}, EvaluatorOptions options = {})
      : twin_(&twin), execution_(std::move(execution)), options_(std::move(options)) {
    require_valid("options", options_);
    if constexpr (!HashableAssembly<Assembly>) {
      if (options_.memoize) {
        throw InvalidArgumentError("options.memoize",
                                   "options.memoize: is true; rule: the twin's Assembly type "
                                   "needs std::hash and == to be memoized");
      }
    }
  }

  Evaluator(const Evaluator&) = delete;
  Evaluator& operator=(const Evaluator&) = delete;

  [[nodiscard]] Index control_dimension() const { return twin_->control_dimension(); }
  [[nodiscard]] decltype(auto) locator_names() const { return twin_->locator_names(); }
  [[nodiscard]] decltype(auto) lower_bounds() const { return twin_->lower_bounds(); }
  [[nodiscard]] decltype(auto) upper_bounds() const { return twin_->upper_bounds(); }
  [[nodiscard]] const T& twin() const noexcept { return *twin_; }
  [[nodiscard]] const E& execution() const noexcept { return execution_; }
  [[nodiscard]] const EvaluatorOptions& options() const noexcept { return options_; }

  /// u0(x) and z*(x) of a twin that knows them (TwinWithOptimum): passed through uncounted, as
  /// they are not evaluations of Q, so an evaluator keeps the twin's exact optimum available.
  [[nodiscard]] decltype(auto) optimum(const Assembly& assembly) const requires TwinWithOptimum<T> {
    return twin_->optimum(assembly);
  }
  [[nodiscard]] double optimal_quality(const Assembly& assembly) const requires TwinWithOptimum<T> {
    return twin_->optimal_quality(assembly);
  }

  /// Q(x, u), as a batch of one.
  [[nodiscard]] double quality(const Assembly& assembly,
                               const Eigen::Ref<const VectorX>& control) const {
    return quality_of_one(*this, assembly, control);
  }

  /// out(j) = Q(x, controls.col(j)), evaluated by the execution policy.
  /// @throws DimensionMismatchError for bad shapes; TwinEvaluationError<Assembly> on a failure.
  void quality_batch(const Assembly& assembly, const Eigen::Ref<const MatrixX>& controls,
                     Eigen::Ref<VectorX> out) const {
    require_control_batch(controls, out, control_dimension());
    // One counter record per call, also when it throws: the twin evaluations it caused (cache
    // hits excluded) and its wall time.
    std::uint64_t evaluated = 0;
    const CallRecord record{counter_, evaluated};
    if (!options_.memoize) {
      evaluated = static_cast<std::uint64_t>(controls.cols());
      evaluate(assembly, controls, out);
      return;
    }
    if constexpr (HashableAssembly<Assembly>) {
      std::vector<Index> misses;
      {
        const std::lock_guard lock(cache_mutex_);
        for (Index j = 0; j < controls.cols(); ++j) {
          const auto it = cache_.find(make_key(assembly, controls.col(j)));
          if (it == cache_.end()) {
            misses.push_back(j);
          } else {
            out(j) = it->second;
          }
        }
      }
      cache_hits_.fetch_add(static_cast<std::uint64_t>(controls.cols()) - misses.size(),
                            std::memory_order_relaxed);
      if (misses.empty()) return;
      const Index k = std::ssize(misses);
      MatrixX missing(controls.rows(), k);
      for (Index i = 0; i < k; ++i)
        missing.col(i) = controls.col(misses[static_cast<std::size_t>(i)]);
      VectorX values(k);
      evaluated = static_cast<std::uint64_t>(k);
      evaluate(assembly, missing, values);
      const std::lock_guard lock(cache_mutex_);
      for (Index i = 0; i < k; ++i) {
        const Index j = misses[static_cast<std::size_t>(i)];
        out(j) = values(i);
        cache_.emplace(make_key(assembly, controls.col(j)), values(i));
      }
    }
  }

  /// m, the key points of a twin that answers their deviations.
  [[nodiscard]] Index key_point_count() const requires TwinWithDeviations<T> {
    return twin_->key_point_count();
  }

  /// out.col(j) = r(x, controls.col(j)), the key points' deviations, evaluated by the execution
  /// policy, counted (one record per call) and checked as quality_batch is.
  /// @throws DimensionMismatchError for bad shapes; TwinEvaluationError<Assembly> on a failure
  ///         (a non-finite deviation names its control).
  void deviations_batch(const Assembly& assembly, const Eigen::Ref<const MatrixX>& controls,
                        Eigen::Ref<MatrixX> out) const requires TwinWithDeviations<T> {
    require_deviations_batch(controls, out, control_dimension(), twin_->key_point_count());
    const auto evaluated = static_cast<std::uint64_t>(controls.cols());
    const CallRecord record{counter_, evaluated};
    execution_.run(controls.cols(), [&](Index begin, Index count) {
      const Eigen::Ref<const MatrixX> part = controls.middleCols(begin, count);
      Eigen::Ref<MatrixX> block = out.middleCols(begin, count);
      call_checked(assembly, part, [&] { twin_->deviations_batch(assembly, part, block); });
      for (Index j = 0; j < count; ++j) {
        for (Index k = 0; k < block.rows(); ++k) {
          if (std::isfinite(block(k, j))) continue;
          throw TwinEvaluationError<Assembly>(
              EvaluationFailure::non_finite, assembly, part, j,
              fmt::format("a deviation is not finite: key point {} is {}; rule: every deviation "
                          "must be finite",
                          k, block(k, j)));
        }
      }
    });
  }

  /// Calls and wall time of quality_batch and deviations_batch calls (`calls`, `elapsed`) and the
  /// twin evaluations they caused (`evaluations`: cache hits excluded), since construction or
  /// reset().
  [[nodiscard]] EvaluationStats stats() const noexcept { return counter_.stats(); }
  [[nodiscard]] const EvaluationCounter& counter() const noexcept { return counter_; }

  /// Controls answered from the cache.
  [[nodiscard]] std::uint64_t cache_hits() const noexcept {
    return cache_hits_.load(std::memory_order_relaxed);
  }
  [[nodiscard]] std::size_t cache_size() const {
    const std::lock_guard lock(cache_mutex_);
    return cache_.size();
  }

  /// Zeroes the statistics (the cache is kept).
  void reset_stats() noexcept {
    counter_.reset();
    cache_hits_.store(0, std::memory_order_relaxed);
  }
  void clear_cache() const {
    const std::lock_guard lock(cache_mutex_);
    cache_.clear();
  }

 private:
  class CallRecord {
   public:
    CallRecord(EvaluationCounter& counter, const std::uint64_t& evaluated) noexcept
        : counter_(counter), evaluated_(evaluated) {}
    CallRecord(const CallRecord&) = delete;
    CallRecord& operator=(const CallRecord&) = delete;
    ~CallRecord() { counter_.record(evaluated_, stopwatch_.elapsed()); }

   private:
    EvaluationCounter& counter_;
    const std::uint64_t& evaluated_;
    Stopwatch stopwatch_;
  };

  struct Key {
    Assembly assembly;
    std::vector<double> control;
    friend bool operator==(const Key&, const Key&) = default;
  };
  struct KeyHash {
    std::size_t operator()(const Key& key) const noexcept {
      std::size_t h = std::hash<Assembly>{}(key.assembly);
      for (const double v : key.control) {
        std::uint64_t bits = 0;
        std::memcpy(&bits, &v, sizeof bits);
        h ^= std::hash<std::uint64_t>{}(bits) + 0x9e3779b97f4a7c15ULL + (h << 6U) + (h >> 2U);
      }
      return h;
    }
  };
  template <typename Column>
  static Key make_key(const Assembly& assembly, const Column& control) {
    return Key{assembly, std::vector<double>(control.data(), control.data() + control.size())};
  }

  void evaluate(const Assembly& assembly, const Eigen::Ref<const MatrixX>& controls,
                Eigen::Ref<VectorX> out) const {
    execution_.run(controls.cols(), [&](Index begin, Index count) {
      call_twin(assembly, controls.middleCols(begin, count), out.segment(begin, count));
    });
  }

  // One twin call, checked.
  void call_twin(const Assembly& assembly, const Eigen::Ref<const MatrixX>& controls,
                 Eigen::Ref<VectorX> out) const {
    call_checked(assembly, controls, [&] { twin_->quality_batch(assembly, controls, out); });
    for (Index j = 0; j < out.size(); ++j) {
      if (std::isfinite(out(j))) continue;
      throw TwinEvaluationError<Assembly>(EvaluationFailure::non_finite, assembly, controls, j,
                                          fmt::format("value is {}; rule: must be finite", out(j)));
    }
  }

  // Runs `call` (one call of the twin at `controls`): its exception, or a call slower than the
  // time limit, becomes a TwinEvaluationError.
  template <typename Call>
  void call_checked(const Assembly& assembly, const Eigen::Ref<const MatrixX>& controls,
                    Call&& call) const {
    const Stopwatch stopwatch;
    try {
      std::forward<Call>(call)();
    } catch (const std::exception& cause) {
      std::throw_with_nested(TwinEvaluationError<Assembly>(EvaluationFailure::twin_threw, assembly,
                                                           controls, std::nullopt, cause.what()));
    } catch (...) {
      std::throw_with_nested(TwinEvaluationError<Assembly>(EvaluationFailure::twin_threw, assembly,
                                                           controls, std::nullopt,
                                                           "an exception of unknown type"));
    }
    const std::chrono::nanoseconds elapsed = stopwatch.elapsed();
    if (options_.time_limit && elapsed > *options_.time_limit) {
      throw TwinEvaluationError<Assembly>(
          EvaluationFailure::time_limit, assembly, controls, std::nullopt,
          fmt::format("the call took {:.6g} s; rule: must finish within {:.6g} s",
                      std::chrono::duration<double>(elapsed).count(),
                      std::chrono::duration<double>(*options_.time_limit).count()));
    }
  }

  const T* twin_;
  E execution_;
  EvaluatorOptions options_;
  mutable EvaluationCounter counter_;
  mutable std::atomic<std::uint64_t> cache_hits_{0};
  mutable std::mutex cache_mutex_;
  mutable std::unordered_map<Key, double, KeyHash> cache_;
};

}  // namespace twincal
