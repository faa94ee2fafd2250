#pragma once
/// @file
/// Execution policies of the Evaluator: how the columns of a batch are spread over threads.
///
/// `Execution` runs `task(begin, count)` over consecutive ranges that cover [0, size) exactly
/// once, returns when all have finished, and rethrows the exception of the first failing range
/// (in range order, so the error does not depend on thread timing). Ranges are disjoint, so tasks
/// that write only their own range need no synchronization, and results stay in input order.

#include <concepts>
#include <functional>
#include <utility>

#include "twincal/core/eigen.hpp"

namespace twincal {

template <typename E>
concept Execution = requires(const E& execution, Index size,
                             const std::function<void(Index, Index)>& task) {
  { execution.concurrency() } -> std::convertible_to<Index>;
  execution.run(size, task);
};

/// Everything on the calling thread, as one range.
class SerialExecution {
 public:
  [[nodiscard]] Index concurrency() const noexcept { return 1; }

  template <typename Task>
  void run(Index size, Task&& task) const {
    if (size > 0) std::forward<Task>(task)(Index{0}, size);
  }
};

static_assert(Execution<SerialExecution>);

}  // namespace twincal
