// huge_pages.h — large host buffers (a CPU backend's grid and sums) on the
// system's transparent huge pages where it offers them on request (Linux's
// THP "madvise" mode, a common default). A render touches cells all over a
// grid of hundreds of MB: in 4 KiB pages nearly every beam's walk misses the
// TLB, in 2 MiB pages the whole grid fits in it (bench/large_site_bench.py's
// linearity row). Internal to the library.
#ifndef VASCO_GPU_SRC_HUGE_PAGES_H
#define VASCO_GPU_SRC_HUGE_PAGES_H

#include <algorithm>
#include <cstddef>
#include <vector>

namespace vasco {

// Asks for huge pages on the whole 2 MiB pages inside [p, p + bytes) that no
// byte of it touched yet (the kernel gives them at the first touch); does
// nothing for a buffer under 4 MiB, off Linux, or where the system says no.
void advise_huge_pages(void *p, size_t bytes);

// v.assign(n, value), a new allocation (when the old one is too small) on
// huge pages: advised before assign touches it. Keeps the allocation when the
// size does not grow, as assign does. A new allocation reserves `capacity`
// elements where that is more than n: address space, not memory (a page
// is resident from its first touch), for a buffer that grows a little at a
// time (a grid whose frame follows its poses) to grow into without moving.
template <class T>
void assign_on_huge_pages(std::vector<T> &v, size_t n, const T &value, size_t capacity = 0) {
  if (v.capacity() < n) {
    std::vector<T>().swap(v);  // the old cells freed first: never both at once
    capacity = std::max(n, capacity);
    v.reserve(capacity);
    advise_huge_pages(v.data(), capacity * sizeof(T));
  }
  v.assign(n, value);
}

}  // namespace vasco

#endif  // VASCO_GPU_SRC_HUGE_PAGES_H
