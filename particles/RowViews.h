// Rows of the pool and views of their values: what the integrators hand the forces, and what
// every per-row kernel reads and writes.
#pragma once

#include <cstddef>

#include "particles/Assert.h"
#include "particles/ParticlePool.h"

namespace tickfx {

/// Rows [begin, end) of the pool.
struct RowRange {
  std::size_t begin = 0;
  std::size_t end = 0;
  Eigen::Index offset() const { return static_cast<Eigen::Index>(begin); }
  Eigen::Index count() const { return static_cast<Eigen::Index>(end - begin); }
};

/// Writable values of three components for the rows of one RowRange: element j of each map
/// belongs to pool row range.begin + j.
struct Vec3Rows {
  Eigen::Map<Eigen::ArrayXf> x, y, z;

  Vec3Rows(float* px, float* py, float* pz, Eigen::Index n) : x(px, n), y(py, n), z(pz, n) {}
  /// Rows `r` of a pool-sized column.
  static Vec3Rows of(Vec3Column& c, RowRange r) {
    TICKFX_ASSERT(r.begin <= r.end && r.end <= static_cast<std::size_t>(c.x.size()),
                  "a row range past the end of its column");
    return {c.x.data() + r.begin, c.y.data() + r.begin, c.z.data() + r.begin, r.count()};
  }
  Eigen::Map<Eigen::ArrayXf>& operator[](int c) { return c == 0 ? x : (c == 1 ? y : z); }
};

/// Read-only values of three components for the rows of one RowRange.
struct ConstVec3Rows {
  Eigen::Map<const Eigen::ArrayXf> x, y, z;

  ConstVec3Rows(const float* px, const float* py, const float* pz, Eigen::Index n)
      : x(px, n), y(py, n), z(pz, n) {}
  const Eigen::Map<const Eigen::ArrayXf>& operator[](int c) const {
    return c == 0 ? x : (c == 1 ? y : z);
  }
};

/// A vector quantity an integrator hands to the forces: row r is at index r − base of each
/// component. The pool's own columns have base 0 and hold every row; an integrator's scratch in a
/// fused pass holds only the rows of the current tile (base = the tile's first row), which is
/// enough because a fused pass only ever runs local modules.
struct Vec3View {
  const float* x = nullptr;
  const float* y = nullptr;
  const float* z = nullptr;
  std::size_t base = 0;

  static Vec3View of(const Vec3Column& c) { return {c.x.data(), c.y.data(), c.z.data(), 0}; }
  /// The values of rows `r`.
  ConstVec3Rows rows(RowRange r) const {
    TICKFX_ASSERT(r.begin >= base && r.begin <= r.end, "rows read below a view's base");
    const std::size_t i = r.begin - base;
    return {x + i, y + i, z + i, r.count()};
  }
  /// The value of one row (non-local modules: any row of a base-0 view).
  Eigen::Vector3f at(std::size_t row) const {
    TICKFX_ASSERT(row >= base, "a row read below a view's base");
    const std::size_t i = row - base;
    return {x[i], y[i], z[i]};
  }
};

}  // namespace tickfx
