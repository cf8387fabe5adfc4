#include "huge_pages.h"

#include <cstdint>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace vasco {

namespace {

constexpr uintptr_t kHugePage = uintptr_t(2) << 20;
constexpr size_t kSmallest = size_t(4) << 20;  // below: at most one whole huge page inside

}  // namespace

void advise_huge_pages(void *p, size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  if (p == nullptr || bytes < kSmallest) return;
  const uintptr_t begin = (reinterpret_cast<uintptr_t>(p) + kHugePage - 1) & ~(kHugePage - 1);
  const uintptr_t end = (reinterpret_cast<uintptr_t>(p) + bytes) & ~(kHugePage - 1);
  // A refusal (THP "never", a kernel without it) leaves ordinary pages: the
  // same cells, only slower to reach; nothing to report.
  if (end > begin) (void)madvise(reinterpret_cast<void *>(begin), end - begin, MADV_HUGEPAGE);
#else
  (void)p;
  (void)bytes;
#endif
}

}  // namespace vasco
