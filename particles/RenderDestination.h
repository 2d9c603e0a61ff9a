// Where a host wants render copies written: its own buffers, any layout, one copy.
#pragma once

#include <cstddef>
#include <cstdint>

namespace tickfx {

/// Rows of three floats in host memory: row i's x at `x + i · rowStride` bytes, its y and z
/// likewise from `y` and `z`. The memory is the host's; tickfx writes rows [0, count) during the
/// copy call only and keeps no pointer.
struct Vec3Destination {
  float* x = nullptr;
  float* y = nullptr;
  float* z = nullptr;
  std::size_t rowStride = 0;  // bytes from one row to the next
  std::size_t capacity = 0;   // rows the buffers hold

  /// x0 y0 z0 x1 y1 z1 …: `xyz` holds 3 · capacity floats (a vertex buffer of points).
  static Vec3Destination interleaved(float* xyz, std::size_t capacity) {
    return {xyz, xyz + 1, xyz + 2, 3 * sizeof(float), capacity};
  }
  /// Three separate columns of `capacity` floats each.
  static Vec3Destination columns(float* x, float* y, float* z, std::size_t capacity) {
    return {x, y, z, sizeof(float), capacity};
  }
  /// x, y, z as three consecutive floats at the start of host records of `recordBytes` each
  /// (a vertex struct whose position comes first; offset `first` for any other place).
  static Vec3Destination records(float* first, std::size_t recordBytes, std::size_t capacity) {
    return {first, first + 1, first + 2, recordBytes, capacity};
  }
};

/// One value per row in host memory: row i at `data + i · rowStride` bytes.
template <typename T>
struct Destination {
  T* data = nullptr;
  std::size_t rowStride = sizeof(T);  // bytes from one row to the next
  std::size_t capacity = 0;           // rows the buffer holds
};

using FloatDestination = Destination<float>;
using IdDestination = Destination<std::uint64_t>;

/// What a copy did: `rows` is the number of particles shown. When it exceeds the destination's
/// capacity nothing was written (call again with room for `rows`), as snprintf does.
struct CopyResult {
  std::size_t rows = 0;
  bool written = false;
};

}  // namespace tickfx
