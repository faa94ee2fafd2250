#include "twincal/core/evaluation_counter.hpp"

#include <stdexcept>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

namespace twincal {
namespace {

using std::chrono::nanoseconds;

TEST(EvaluationCounter, RecordsCallsEvaluationsAndTime) {
  EvaluationCounter counter;
  counter.record(8, nanoseconds(100));
  counter.record(4, nanoseconds(50));
  const EvaluationStats stats = counter.stats();
  EXPECT_EQ(stats.calls, 2U);
  EXPECT_EQ(stats.evaluations, 12U);
  EXPECT_EQ(stats.elapsed, nanoseconds(150));
  EXPECT_DOUBLE_EQ(stats.seconds(), 150e-9);
  counter.reset();
  EXPECT_EQ(counter.stats(), EvaluationStats{});
}

TEST(EvaluationCounter, PerStepFiguresAreSnapshotDifferences) {
  EvaluationCounter counter;
  counter.record(7, nanoseconds(10));
  const EvaluationStats before = counter.stats();
  counter.record(5, nanoseconds(20));
  const EvaluationStats step = counter.stats() - before;
  EXPECT_EQ(step, (EvaluationStats{1, 5, nanoseconds(20)}));
}

TEST(EvaluationCounter, ScopeRecordsAlsoWhenTheCallThrows) {
  EvaluationCounter counter;
  {
    const EvaluationCounter::Scope scope = counter.scope(3);
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  try {
    const EvaluationCounter::Scope scope = counter.scope(2);
    throw std::runtime_error("twin failed");
  } catch (const std::runtime_error&) {
  }
  const EvaluationStats stats = counter.stats();
  EXPECT_EQ(stats.calls, 2U);
  EXPECT_EQ(stats.evaluations, 5U);
  EXPECT_GE(stats.elapsed, std::chrono::milliseconds(2));
}

TEST(EvaluationCounter, ConcurrentRecordsAreNotLost) {
  EvaluationCounter counter;
  std::vector<std::thread> workers;
  for (int t = 0; t < 4; ++t) {
    workers.emplace_back([&counter] {
      for (int i = 0; i < 10000; ++i) counter.record(2, nanoseconds(1));
    });
  }
  for (std::thread& worker : workers) worker.join();
  EXPECT_EQ(counter.stats(), (EvaluationStats{40000, 80000, nanoseconds(40000)}));
}

}  // namespace
}  // namespace twincal
