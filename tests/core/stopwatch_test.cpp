#include "twincal/core/stopwatch.hpp"

#include <thread>

#include <gtest/gtest.h>

namespace twincal {
namespace {

TEST(Stopwatch, MeasuresAtLeastTheSleptTimeAndRestarts) {
  Stopwatch watch;
  std::this_thread::sleep_for(std::chrono::milliseconds(5));
  EXPECT_GE(watch.elapsed(), std::chrono::milliseconds(5));
  EXPECT_GE(watch.seconds(), 0.005);
  watch.restart();
  EXPECT_LT(watch.elapsed(), std::chrono::milliseconds(5));
}

}  // namespace
}  // namespace twincal
