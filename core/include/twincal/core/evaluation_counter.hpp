#pragma once
/// @file
/// `EvaluationCounter`: counts black-box evaluations (Q-evaluations of a twin, measurement
/// function calls of a filter) and the wall time spent in them. Thread-safe, so a parallel
/// evaluator's workers record into one counter. Per-step figures come from the difference of
/// two snapshots: `counter.stats() - before`.

#include <atomic>
#include <chrono>
#include <cstdint>

#include "twincal/core/stopwatch.hpp"

namespace twincal {

/// A snapshot of an EvaluationCounter.
struct EvaluationStats {
  std::uint64_t calls = 0;              ///< batch calls (one call may evaluate many points)
  std::uint64_t evaluations = 0;        ///< points evaluated
  std::chrono::nanoseconds elapsed{0};  ///< wall time inside the calls

  [[nodiscard]] double seconds() const noexcept {
    return std::chrono::duration<double>(elapsed).count();
  }

  friend EvaluationStats operator-(const EvaluationStats& after, const EvaluationStats& before) {
    return {after.calls - before.calls, after.evaluations - before.evaluations,
            after.elapsed - before.elapsed};
  }
  friend bool operator==(const EvaluationStats&, const EvaluationStats&) = default;
};

class EvaluationCounter {
 public:
  /// Records one call that evaluated `evaluations` points in `elapsed` wall time.
  void record(std::uint64_t evaluations, std::chrono::nanoseconds elapsed) noexcept {
    calls_.fetch_add(1, std::memory_order_relaxed);
    evaluations_.fetch_add(evaluations, std::memory_order_relaxed);
    nanoseconds_.fetch_add(elapsed.count(), std::memory_order_relaxed);
  }

  [[nodiscard]] EvaluationStats stats() const noexcept {
    return {calls_.load(std::memory_order_relaxed), evaluations_.load(std::memory_order_relaxed),
            std::chrono::nanoseconds(nanoseconds_.load(std::memory_order_relaxed))};
  }

  void reset() noexcept {
    calls_.store(0, std::memory_order_relaxed);
    evaluations_.store(0, std::memory_order_relaxed);
    nanoseconds_.store(0, std::memory_order_relaxed);
  }

  /// RAII: times its own lifetime and records it as one call of `evaluations` points, also when
  /// the timed call throws (a failed evaluation still cost time and counts).
  class Scope {
   public:
    Scope(EvaluationCounter& counter, std::uint64_t evaluations) noexcept
        : counter_(counter), evaluations_(evaluations) {}
    Scope(const Scope&) = delete;
    Scope& operator=(const Scope&) = delete;
    ~Scope() { counter_.record(evaluations_, stopwatch_.elapsed()); }

   private:
    EvaluationCounter& counter_;
    std::uint64_t evaluations_;
    Stopwatch stopwatch_;
  };

  [[nodiscard]] Scope scope(std::uint64_t evaluations) noexcept { return {*this, evaluations}; }

 private:
  std::atomic<std::uint64_t> calls_{0};
  std::atomic<std::uint64_t> evaluations_{0};
  std::atomic<std::int64_t> nanoseconds_{0};
};

}  // namespace twincal
