#include "allocation_counting.hpp"

#include <atomic>
#include <cstddef>

// GCC announces ASan with __SANITIZE_ADDRESS__, Clang 14 only through __has_feature.
#if defined(__SANITIZE_ADDRESS__)
#define TWINCAL_ADDRESS_SANITIZER 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define TWINCAL_ADDRESS_SANITIZER 1
#endif
#endif

namespace {
std::atomic<bool> counting{false};
std::atomic<long> allocations{0};
}  // namespace

#if !defined(TWINCAL_ADDRESS_SANITIZER)
// glibc's own allocator stays reachable through its __libc_ names.
extern "C" {
void* __libc_malloc(std::size_t size);
void* __libc_calloc(std::size_t count, std::size_t size);
void* __libc_realloc(void* pointer, std::size_t size);
void* malloc(std::size_t size) {
  if (counting.load(std::memory_order_relaxed)) allocations.fetch_add(1);
  return __libc_malloc(size);
}
void* calloc(std::size_t count, std::size_t size) {
  if (counting.load(std::memory_order_relaxed)) allocations.fetch_add(1);
  return __libc_calloc(count, size);
}
void* realloc(void* pointer, std::size_t size) {
  if (counting.load(std::memory_order_relaxed)) allocations.fetch_add(1);
  return __libc_realloc(pointer, size);
}
}
#endif

namespace twincal::test_support {

bool counts_allocations() noexcept {
#if defined(TWINCAL_ADDRESS_SANITIZER)
  return false;
#else
  return true;
#endif
}

void start_counting_allocations() noexcept {
  allocations.store(0);
  counting.store(true);
}

long stop_counting_allocations() noexcept {
  counting.store(false);
  return allocations.load();
}

}  // namespace twincal::test_support
