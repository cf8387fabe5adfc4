// The largest single allocation a test program made, to show that sizes
// claimed by a file are not allocated before the file proves it holds them.
// Including this header replaces the global operator new and delete of the
// test program: include it from the program's one source file only. (GCC
// cannot see that the replaced new and delete pair malloc with free, hence
// the pragma.)
#ifndef VASCO_TESTS_LARGEST_ALLOC_SUPPORT_H
#define VASCO_TESTS_LARGEST_ALLOC_SUPPORT_H

#include <atomic>
#include <cstddef>
#include <cstdlib>
#include <new>

#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
#endif

namespace alloctest {

inline std::atomic<size_t> g_largest_alloc{0};

inline void note_alloc(size_t n) {
  size_t cur = g_largest_alloc.load(std::memory_order_relaxed);
  while (n > cur && !g_largest_alloc.compare_exchange_weak(cur, n, std::memory_order_relaxed)) {
  }
}

constexpr size_t kAllocLimit = size_t{64} << 20;  // far below every claim the tests use

}  // namespace alloctest

void *operator new(size_t n) {
  alloctest::note_alloc(n);
  if (void *p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void *operator new[](size_t n) {
  alloctest::note_alloc(n);
  if (void *p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void operator delete(void *p) noexcept { std::free(p); }
void operator delete[](void *p) noexcept { std::free(p); }
void operator delete(void *p, size_t) noexcept { std::free(p); }
void operator delete[](void *p, size_t) noexcept { std::free(p); }

#endif  // VASCO_TESTS_LARGEST_ALLOC_SUPPORT_H
