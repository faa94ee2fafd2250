#pragma once
// Counts the heap allocations a piece of code makes, for the tests that prove filter steps
// allocate nothing. Eigen allocates with malloc, so allocation_counting.cpp interposes malloc,
// calloc and realloc themselves. Sanitizers interpose malloc too: there, nothing is counted.

namespace twincal::test_support {

/// False under AddressSanitizer, whose own malloc cannot be interposed again.
[[nodiscard]] bool counts_allocations() noexcept;

void start_counting_allocations() noexcept;
[[nodiscard]] long stop_counting_allocations() noexcept;

/// The malloc, calloc and realloc calls made by `work()` (0 when nothing is counted).
template <typename Work>
[[nodiscard]] long allocations_in(Work&& work) {
  start_counting_allocations();
  work();
  return stop_counting_allocations();
}

}  // namespace twincal::test_support
