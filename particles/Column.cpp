#include "particles/Column.h"

#include <cstdlib>
#include <new>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace tickfx {

namespace {

// In a virtual machine each page fault costs microseconds: a fresh 240 MB took 0.7–0.95 s to
// touch with 4 KiB pages and 27 ms with huge pages (docs/performance.md). The size is not rounded
// up to 2 MiB: the last part of a page stays in 4 KiB pages, so no column holds memory it never
// writes.
constexpr std::size_t kHugePage = std::size_t{2} << 20;

}  // namespace

void* allocateColumnStorage(std::size_t bytes) {
  const std::size_t alignment = bytes >= kHugePage ? kHugePage : OffsetBuffer<char>::kAlignment;
  void* p = nullptr;
  if (::posix_memalign(&p, alignment, bytes) != 0) throw std::bad_alloc();
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  if (alignment == kHugePage) ::madvise(p, bytes / kHugePage * kHugePage, MADV_HUGEPAGE);  // a hint
#endif
  return p;
}

}  // namespace tickfx
