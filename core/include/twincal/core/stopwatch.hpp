#pragma once
/// @file
/// `Stopwatch`: monotonic wall time since construction or the last restart.

#include <chrono>

namespace twincal {

class Stopwatch {
 public:
  using Clock = std::chrono::steady_clock;

  Stopwatch() noexcept : start_(Clock::now()) {}

  void restart() noexcept { start_ = Clock::now(); }

  [[nodiscard]] std::chrono::nanoseconds elapsed() const noexcept {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - start_);
  }

  [[nodiscard]] double seconds() const noexcept {
    return std::chrono::duration<double>(elapsed()).count();
  }

 private:
  Clock::time_point start_;
};

}  // namespace twincal
