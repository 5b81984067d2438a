// A global operator new that counts the bytes live on the heap and refuses (std::bad_alloc) an allocation
// that would take them past a cap the test sets: a test of "memory linear in the input" then fails fast
// instead of taking the machine's memory. It replaces the allocation functions of the whole executable:
// include it in exactly one translation unit, and never together with counting_allocator.hpp.
#pragma once

// g++ cannot see that every operator new here is malloc and pairs it with a sized delete.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
#endif

#include <malloc.h>

#include <atomic>
#include <cstddef>
#include <cstdlib>
#include <new>

namespace dyncull {
namespace test {
struct HeapBytes {
  std::atomic<std::size_t> live{0}, peak{0}, cap{0};  // cap 0: no cap
};
inline HeapBytes& heap_bytes() {
  static HeapBytes bytes;
  return bytes;
}

/// While alive: allocations past `cap` live bytes throw std::bad_alloc; peak() is the most held since.
class HeapCap {
 public:
  explicit HeapCap(std::size_t cap) {
    heap_bytes().peak = heap_bytes().live.load();
    start_ = heap_bytes().live.load();
    heap_bytes().cap = start_ + cap;
  }
  ~HeapCap() { heap_bytes().cap = 0; }
  HeapCap(const HeapCap&) = delete;
  HeapCap& operator=(const HeapCap&) = delete;
  /// The most bytes held at once above what was held when the cap was set.
  std::size_t peak() const { return heap_bytes().peak.load() - start_; }

 private:
  std::size_t start_ = 0;
};

inline void* capped_malloc(std::size_t size) {
  HeapBytes& h = heap_bytes();
  const std::size_t cap = h.cap.load(std::memory_order_relaxed);
  if (cap != 0 && h.live.load(std::memory_order_relaxed) + size > cap) return nullptr;
  void* p = std::malloc(size == 0 ? 1 : size);
  if (!p) return nullptr;
  const std::size_t now = h.live.fetch_add(malloc_usable_size(p), std::memory_order_relaxed) + malloc_usable_size(p);
  std::size_t peak = h.peak.load(std::memory_order_relaxed);
  while (now > peak && !h.peak.compare_exchange_weak(peak, now, std::memory_order_relaxed)) {
  }
  return p;
}
inline void capped_free(void* p) {
  if (!p) return;
  heap_bytes().live.fetch_sub(malloc_usable_size(p), std::memory_order_relaxed);
  std::free(p);
}
}  // namespace test
}  // namespace dyncull

void* operator new(std::size_t size) {
  if (void* p = dyncull::test::capped_malloc(size)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) { return ::operator new(size); }
void operator delete(void* p) noexcept { dyncull::test::capped_free(p); }
void operator delete[](void* p) noexcept { dyncull::test::capped_free(p); }
void operator delete(void* p, std::size_t) noexcept { dyncull::test::capped_free(p); }
void operator delete[](void* p, std::size_t) noexcept { dyncull::test::capped_free(p); }
void* operator new(std::size_t size, const std::nothrow_t&) noexcept { return dyncull::test::capped_malloc(size); }
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept { return dyncull::test::capped_malloc(size); }
void operator delete(void* p, const std::nothrow_t&) noexcept { dyncull::test::capped_free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { dyncull::test::capped_free(p); }
