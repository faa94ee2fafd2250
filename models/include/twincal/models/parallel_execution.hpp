#pragma once
/// @file
/// `ParallelExecution`: spreads a batch over a Boost.Asio thread pool.
///
/// A batch of `size` columns is cut into min(size, threads · chunks_per_thread) contiguous
/// ranges of near-equal length, each posted as one task; the calling thread waits on a latch.
/// One range is one call of the twin's batch interface, so an expensive black box with uniform
/// cost is best served by one range per thread (the default); more ranges per thread balance
/// uneven costs at the price of more calls. Exceptions are captured per range and the first one
/// (in range order) is rethrown after every range has finished, so no task outlives the call.

#include <algorithm>
#include <cstddef>
#include <exception>
#include <latch>
#include <memory>
#include <vector>

#include <fmt/format.h>
#include <boost/asio/post.hpp>
#include <boost/asio/thread_pool.hpp>

#include "twincal/core/eigen.hpp"
#include "twincal/core/error.hpp"
#include "twincal/models/execution.hpp"

namespace twincal {

class ParallelExecution {
 public:
  /// A pool of `threads` workers (≥ 1), `chunks_per_thread` ranges per worker and batch (≥ 1).
  /// @throws InvalidArgumentError for zero threads or chunks.
  explicit ParallelExecution(Index threads, Index chunks_per_thread = 1)
      : threads_(threads), chunks_per_thread_(chunks_per_thread) {
    if (threads < 1) {
      throw InvalidArgumentError("threads",
                                 fmt::format("threads: value is {}; rule: must be >= 1", threads));
    }
    if (chunks_per_thread < 1) {
      throw InvalidArgumentError(
          "chunks_per_thread",
          fmt::format("chunks_per_thread: value is {}; rule: must be >= 1", chunks_per_thread));
    }
    pool_ = std::make_unique<boost::asio::thread_pool>(static_cast<std::size_t>(threads));
  }

  ParallelExecution(ParallelExecution&&) noexcept = default;
  ParallelExecution& operator=(ParallelExecution&&) noexcept = default;
  ParallelExecution(const ParallelExecution&) = delete;
  ParallelExecution& operator=(const ParallelExecution&) = delete;

  ~ParallelExecution() {
    if (pool_) pool_->join();
  }

  [[nodiscard]] Index concurrency() const noexcept { return threads_; }

  template <typename Task>
  void run(Index size, Task&& task) const {
    if (size <= 0) return;
    const Index ranges = std::min(size, threads_ * chunks_per_thread_);
    std::vector<std::exception_ptr> errors(static_cast<std::size_t>(ranges));
    std::latch done(static_cast<std::ptrdiff_t>(ranges));
    for (Index r = 0; r < ranges; ++r) {
      // Range r covers [r·size/ranges, (r+1)·size/ranges): lengths differ by at most one.
      const Index begin = r * size / ranges;
      const Index end = (r + 1) * size / ranges;
      boost::asio::post(*pool_, [&task, &errors, &done, r, begin, end] {
        try {
          task(begin, end - begin);
        } catch (...) {
          errors[static_cast<std::size_t>(r)] = std::current_exception();
        }
        done.count_down();
      });
    }
    done.wait();
    for (const std::exception_ptr& error : errors) {
      if (error) std::rethrow_exception(error);
    }
  }

 private:
  Index threads_;
  Index chunks_per_thread_;
  std::unique_ptr<boost::asio::thread_pool> pool_;
};

static_assert(Execution<ParallelExecution>);

}  // namespace twincal
