// A counting global operator new for the tests that hold code to "no heap allocation per frame". It
// replaces the allocation functions of the whole executable, so include it in exactly one translation unit
// (a test file that includes it gets its own executable: tests/CMakeLists.txt) and read the count with
// dyncull::test::allocations().
#pragma once

// g++ cannot see that every operator new here is malloc and pairs it with a sized delete.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
#endif

#include <atomic>
#include <cstddef>
#include <cstdlib>
#include <new>

namespace dyncull {
namespace test {
inline std::atomic<std::size_t>& allocation_counter() {
  static std::atomic<std::size_t> count{0};
  return count;
}
/// Heap allocations through operator new (any form) since the program started.
inline std::size_t allocations() { return allocation_counter().load(); }
}  // namespace test
}  // namespace dyncull

void* operator new(std::size_t size) {
  dyncull::test::allocation_counter().fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) { return ::operator new(size); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
// The nothrow forms too (std::stable_sort's temporary buffer uses them): under AddressSanitizer they would
// otherwise come from its allocator and be freed by the delete above.
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  dyncull::test::allocation_counter().fetch_add(1, std::memory_order_relaxed);
  return std::malloc(size == 0 ? 1 : size);
}
void* operator new[](std::size_t size, const std::nothrow_t& tag) noexcept { return ::operator new(size, tag); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }
