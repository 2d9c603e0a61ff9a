// A std::vector whose resize() leaves new elements uninitialised: for large columns a parallel
// loop fills right after, where a zero-fill would be a serial pass over the whole of them (and
// would take every page's first-touch fault on one thread). Its storage is a column's (huge pages
// when large), for the same reason.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdlib>
#include <memory>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

#include "particles/Column.h"

namespace tickfx::io {

/// A stateless allocator of column storage (allocateColumnStorage: huge pages for 2 MiB or
/// more) whose construction with no arguments default-initialises (leaves a trivial type's bytes
/// as they are) instead of value-initialising (zeroing).
template <typename T>
class DefaultInitAllocator {
 public:
  using value_type = T;
  DefaultInitAllocator() = default;
  template <typename U>
  DefaultInitAllocator(const DefaultInitAllocator<U>&) noexcept {}

  T* allocate(std::size_t n) {
    if (n > std::size_t(-1) / 2 / sizeof(T)) throw std::bad_array_new_length();
    // Whole lines, at least one, as a column's own storage (OffsetBuffer) asks.
    constexpr std::size_t kLine = OffsetBuffer<char>::kAlignment;
    const std::size_t bytes = std::max((n * sizeof(T) + kLine - 1) / kLine * kLine, kLine);
    return static_cast<T*>(allocateColumnStorage(bytes));
  }
  void deallocate(T* p, std::size_t) noexcept { std::free(p); }

  template <typename U>
  void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
    ::new (static_cast<void*>(p)) U;
  }
  template <typename U, typename... Args>
  void construct(U* p, Args&&... args) {
    std::construct_at(p, std::forward<Args>(args)...);
  }
  template <typename U>
  bool operator==(const DefaultInitAllocator<U>&) const noexcept {
    return true;
  }
};

/// A vector of trivial values that resize() and the sized constructor do not initialise: the
/// caller writes every new element before reading it.
template <typename T>
using UninitialisedVector = std::vector<T, DefaultInitAllocator<T>>;

}  // namespace tickfx::io
