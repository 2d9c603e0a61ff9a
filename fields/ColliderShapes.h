// Internal to the colliders (not installed): the analytic shapes in their rest frame.
//
// Every shape is already grown (outside) or shrunk (inside) by the particles' radius, and its
// phi(x) is the signed distance of a particle centre to the region it may not enter: >= 0 where
// it may be, < 0 inside the forbidden region. Products and sums are written out component by
// component, in a fixed order, so no library or vectoriser can reorder them.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>

#include "particles/Isa.h"

namespace tickfx::collide {

using V3 = Eigen::Vector3f;

inline float dot(const V3& a, const V3& b) { return a.x() * b.x() + a.y() * b.y() + a.z() * b.z(); }
inline float maxAbs(const V3& a) {
  return std::max(std::fabs(a.x()), std::max(std::fabs(a.y()), std::fabs(a.z())));
}
// m · v and mᵀ · v with the sums in column order.
inline V3 mul(const Eigen::Matrix3f& m, const V3& v) {
  return V3(m(0, 0) * v.x() + m(0, 1) * v.y() + m(0, 2) * v.z(),
            m(1, 0) * v.x() + m(1, 1) * v.y() + m(1, 2) * v.z(),
            m(2, 0) * v.x() + m(2, 1) * v.y() + m(2, 2) * v.z());
}
inline V3 mulTransposed(const Eigen::Matrix3f& m, const V3& v) {
  return V3(m(0, 0) * v.x() + m(1, 0) * v.y() + m(2, 0) * v.z(),
            m(0, 1) * v.x() + m(1, 1) * v.y() + m(2, 1) * v.z(),
            m(0, 2) * v.x() + m(1, 2) * v.y() + m(2, 2) * v.z());
}
inline V3 cross(const V3& a, const V3& b) {
  return V3(a.y() * b.z() - a.z() * b.y(), a.z() * b.x() - a.x() * b.z(),
            a.x() * b.y() - a.y() * b.x());
}
inline float length(const V3& a) { return std::sqrt(dot(a, a)); }

/// Where a rest-frame segment a → b first enters the forbidden region: at s in [0, 1].
struct Entry {
  float s = 0.0f;
  // phi's rate of change along the path at the crossing, per metre, where the shape measured it
  // (a level set, from the two samples that bracket the crossing); 0 where its normal is exact.
  float slope = 0.0f;
};

/// `n`, turned if need be so that the path `d` approaches it as steeply as phi fell along the path
/// (`slope` < 0, per metre), unit length. A sampled gradient need not face the path that crossed:
/// for a grain sliding on a level set, its path all but tangent, the gradient can say the path
/// leaves, the response then keeps the velocity, and the particle met the surface again and again
/// at the same point, gaining speed. A gradient that says the path falls at least half as fast
/// is kept: the march's bracket can span more than the stretch where phi is linear (the edge of
/// a narrow band), so there the slope is the cruder of the two.
inline V3 facingPath(const V3& n, const V3& d, float slope) {
  const V3 u = d / length(d);
  const float along = dot(n, u);
  if (along <= 0.5f * slope) return n;
  const V3 m = n + u * (slope - along);
  return m / length(m);
}

/// Whether the boxes around a → b and [lo, hi] overlap.
inline bool boxesMeet(const V3& a, const V3& b, const V3& lo, const V3& hi) {
  return std::max(a.x(), b.x()) >= lo.x() && std::min(a.x(), b.x()) <= hi.x() &&
         std::max(a.y(), b.y()) >= lo.y() && std::min(a.y(), b.y()) <= hi.y() &&
         std::max(a.z(), b.z()) >= lo.z() && std::min(a.z(), b.z()) <= hi.z();
}

// flags[i] |= rowFlag(a's x, y, z, b's x, y, z) (0 or 1) for rows [0, n), a screen over a block's
// start and end columns. Restricted copies of the pointers: the flags are bytes, which may alias
// anything, so without them the compiler reloads every pointer and bound a row and does not
// vectorise (measured: scalar). A rowFlag without branches vectorises; columns it ignores are not
// read.
template <class RowFlag>
inline void screenRowsAs(const float* const a[3], const float* const b[3], std::size_t n,
                         std::uint8_t* flags, const RowFlag& rowFlag) {
  const float* __restrict ax = a[0];
  const float* __restrict ay = a[1];
  const float* __restrict az = a[2];
  const float* __restrict bx = b[0];
  const float* __restrict by = b[1];
  const float* __restrict bz = b[2];
  std::uint8_t* __restrict f = flags;
  for (std::size_t i = 0; i < n; ++i)
    f[i] = static_cast<std::uint8_t>(f[i] | rowFlag(ax[i], ay[i], az[i], bx[i], by[i], bz[i]));
}

#ifdef TICKFX_AVX2_CLONES
// screenRowsAs() vectorised for AVX2 and AVX-512 (the update loops' paths, particles/Isa.h), the
// row flag inlined (flatten). Comparisons of values computed by the same IEEE operations at any
// width: the same flags on every path (test_colliders holds them to the baseline's).
template <class RowFlag>
[[gnu::noinline, gnu::target("avx2"), gnu::flatten]] void screenRowsAvx2(const float* const a[3],
                                                                         const float* const b[3],
                                                                         std::size_t n,
                                                                         std::uint8_t* flags,
                                                                         const RowFlag& rowFlag) {
  screenRowsAs(a, b, n, flags, rowFlag);
}
template <class RowFlag>
[[gnu::noinline, gnu::target("avx2,avx512f"), gnu::flatten]] void screenRowsAvx512(
    const float* const a[3], const float* const b[3], std::size_t n, std::uint8_t* flags,
    const RowFlag& rowFlag) {
  screenRowsAs(a, b, n, flags, rowFlag);
}
#endif

// screenRowsAs() on the path activeIsa() names.
template <class RowFlag>
inline void screenRows(const float* const a[3], const float* const b[3], std::size_t n,
                       std::uint8_t* flags, const RowFlag& rowFlag) {
#ifdef TICKFX_AVX2_CLONES
  switch (activeIsa()) {
    case Isa::Avx512:
      return screenRowsAvx512(a, b, n, flags, rowFlag);
    case Isa::Avx2:
      return screenRowsAvx2(a, b, n, flags, rowFlag);
    case Isa::Baseline:
      break;
  }
#endif
  screenRowsAs(a, b, n, flags, rowFlag);
}

// flags[i] = 1 for rows [0, n) whose path a → b has a box meeting [lo, hi]: boxesMeet over
// columns, without a branch a row, so that the compiler vectorises it.
inline void screenBoxColumns(const float* const a[3], const float* const b[3], std::size_t n,
                             const V3& lo, const V3& hi, std::uint8_t* flags) {
  const float lx = lo.x(), ly = lo.y(), lz = lo.z(), hx = hi.x(), hy = hi.y(), hz = hi.z();
  screenRows(a, b, n, flags, [=](float ax, float ay, float az, float bx, float by, float bz) {
    // Integers, not bools: & on every comparison, no short circuit to branch on.
    return static_cast<int>(std::max(ax, bx) >= lx) & static_cast<int>(std::min(ax, bx) <= hx) &
           static_cast<int>(std::max(ay, by) >= ly) & static_cast<int>(std::min(ay, by) <= hy) &
           static_cast<int>(std::max(az, bz) >= lz) & static_cast<int>(std::min(az, bz) <= hz);
  });
}

// How far a shape's screening box reaches past it: far more than the rounding of a contact test
// (8 ulps), so that every path a test would find a contact on is screened in.
inline float screenSlack(float extent) { return (1.0f + extent) * 0x1p-12f; }

/// A half-space: forbidden where side · (n · (x − p)) < radius.
struct PlaneShape {
  V3 point, normal;  // normal unit, pointing to the allowed side
  float offset;      // the particles' radius

  float phi(const V3& x) const { return dot(normal, x - point) - offset; }
  V3 normalAt(const V3& /*x*/) const { return normal; }
  // A contact needs an end below −tolerance (linear between them): exact, not a bound.
  bool mayTouch(const V3& a, const V3& b) const { return phi(a) < 0.0f || phi(b) < 0.0f; }
  // mayTouch over columns: phi's operations in phi's order, no branch a row.
  void screenColumns(const float* const a[3], const float* const b[3], std::size_t n,
                     std::uint8_t* flags) const {
    const float nx = normal.x(), ny = normal.y(), nz = normal.z();
    const float px = point.x(), py = point.y(), pz = point.z(), r = offset;
    // An axis-aligned normal (a ground plane's): phi is ±(x_axis − p_axis) − r, the other terms
    // being 0 · (finite) = ±0, so one column decides. (Where a coordinate is not finite phi is
    // NaN and flags nothing; this may flag such a row, which the exact test then refuses.)
    const int axis = axisOf();
    if (axis >= 0) {
      const float sign = normal[axis], p = point[axis];
      const float* const aa[3] = {a[axis], a[axis], a[axis]};
      const float* const ba[3] = {b[axis], b[axis], b[axis]};
      screenRows(aa, ba, n, flags, [=](float ac, float, float, float bc, float, float) {
        return static_cast<int>(sign * (ac - p) - r < 0.0f) |
               static_cast<int>(sign * (bc - p) - r < 0.0f);
      });
      return;
    }
    screenRows(a, b, n, flags, [=](float ax, float ay, float az, float bx, float by, float bz) {
      const float da = nx * (ax - px) + ny * (ay - py) + nz * (az - pz) - r;
      const float db = nx * (bx - px) + ny * (by - py) + nz * (bz - pz) - r;
      return static_cast<int>(da < 0.0f) | static_cast<int>(db < 0.0f);
    });
  }
  // Collider::screenSpan() of screenColumns(): only an axis-aligned normal's screen reads one
  // axis alone. With sign +1 it flags a path only where (c − p) − r < 0 at an end, which needs
  // c < p + r exactly (float subtraction rounds monotonically and keeps the sign of the exact
  // difference); with −1 only where c > p − r. p ± r is rounded once, and the slack is far more.
  bool screenSpan(int axis, float& lo, float& hi) const {
    if (axisOf() != axis || std::fabs(normal[axis]) != 1.0f) return false;
    const float p = point[axis], r = offset, slack = screenSlack(std::fabs(p) + std::fabs(r));
    constexpr float kInf = std::numeric_limits<float>::infinity();
    lo = normal[axis] > 0.0f ? -kInf : (p - r) - slack;
    hi = normal[axis] > 0.0f ? (p + r) + slack : kInf;
    return true;
  }
  // The axis of an axis-aligned normal, else −1.
  int axisOf() const {
    const float nx = normal.x(), ny = normal.y(), nz = normal.z();
    return ny == 0.0f && nz == 0.0f   ? 0
           : nx == 0.0f && nz == 0.0f ? 1
           : nx == 0.0f && ny == 0.0f ? 2
                                      : -1;
  }
  bool entry(const V3& a, const V3& b, float tolerance, Entry& e) const {
    const float pa = phi(a), pb = phi(b);
    if (pa < -tolerance) {
      e.s = 0.0f;
      return true;
    }
    if (!(pb < -tolerance)) return false;
    e.s = pa > 0.0f ? pa / (pa - pb) : 0.0f;
    return true;
  }
};

/// A ball of radius rho around `center`, forbidden inside (obstacle) or outside (container).
struct SphereShape {
  V3 center;
  float rho;  // the sphere's radius grown (obstacle) or shrunk (container) by the particles'
  bool container;

  // A container is convex: a path between two points inside it stays inside. An obstacle: the
  // boxes around the path and the ball meet.
  bool mayTouch(const V3& a, const V3& b) const {
    if (container) return phi(a) < 0.0f || phi(b) < 0.0f;
    const float r = rho + screenSlack(maxAbs(center) + rho);
    return boxesMeet(a, b, center - V3::Constant(r), center + V3::Constant(r));
  }
  // An obstacle's box over columns; false for a container (its rows go through mayTouch).
  bool screenBox(V3& lo, V3& hi) const {
    const float r = rho + screenSlack(maxAbs(center) + rho);
    lo = center - V3::Constant(r);
    hi = center + V3::Constant(r);
    return !container;
  }

  float phi(const V3& x) const {
    const float d = length(x - center) - rho;
    return container ? -d : d;
  }
  V3 normalAt(const V3& x) const {
    const V3 r = x - center;
    const float l = length(r);
    if (!(l > 0.0f)) return V3(0.0f, container ? -1.0f : 1.0f, 0.0f);
    const V3 n = r / l;
    return container ? V3(-n) : n;
  }
  bool entry(const V3& a, const V3& b, float tolerance, Entry& e) const {
    const float pa = phi(a), pb = phi(b);
    if (pa < -tolerance) {
      e.s = 0.0f;
      return true;
    }
    const V3 m = a - center, d = b - a;
    const float A = dot(d, d), B = dot(m, d), C = dot(m, m) - rho * rho;
    const float disc = B * B - A * C;
    if (!container) {
      // Both ends outside: the path may still pass through the ball (entering, then leaving).
      const bool through = pb >= -tolerance && C >= 0.0f && B < 0.0f && disc > 0.0f && -B < A;
      if (!(pb < -tolerance) && !through) return false;
      const float s = A > 0.0f && disc >= 0.0f ? (-B - std::sqrt(disc)) / A : 0.0f;
      e.s = std::clamp(s, 0.0f, 1.0f);
      return true;
    }
    if (!(pb < -tolerance)) return false;  // a container is convex: the path leaves it only there
    const float s = A > 0.0f && disc >= 0.0f ? (-B + std::sqrt(disc)) / A : 0.0f;
    e.s = std::clamp(s, 0.0f, 1.0f);
    return true;
  }
};

/// A box of half edges `half` around `center`, rotated by `rotation` (its frame to the rest
/// frame), forbidden inside (obstacle) or outside (container). The particles' radius grows or
/// shrinks each half edge (corners stay sharp).
struct BoxShape {
  V3 center, half;
  Eigen::Matrix3f rotation;
  bool container;

  V3 local(const V3& x) const { return mulTransposed(rotation, x - center); }
  // A container is convex (see SphereShape); an obstacle's box around its rotated corners.
  bool mayTouch(const V3& a, const V3& b) const {
    if (container) return phi(a) < 0.0f || phi(b) < 0.0f;
    V3 lo, hi;
    screenBox(lo, hi);
    return boxesMeet(a, b, lo, hi);
  }
  // The box around the rotated corners; false for a container (see SphereShape).
  bool screenBox(V3& lo, V3& hi) const {
    V3 reach;
    for (int i = 0; i < 3; ++i) {
      reach[i] = std::fabs(rotation(i, 0)) * half.x() + std::fabs(rotation(i, 1)) * half.y() +
                 std::fabs(rotation(i, 2)) * half.z();
    }
    reach += V3::Constant(screenSlack(maxAbs(center) + maxAbs(reach)));
    lo = center - reach;
    hi = center + reach;
    return !container;
  }
  // The box's signed distance in its own frame.
  float sdf(const V3& l) const {
    const V3 q(std::fabs(l.x()) - half.x(), std::fabs(l.y()) - half.y(),
               std::fabs(l.z()) - half.z());
    const V3 o(std::max(q.x(), 0.0f), std::max(q.y(), 0.0f), std::max(q.z(), 0.0f));
    return length(o) + std::min(std::max(q.x(), std::max(q.y(), q.z())), 0.0f);
  }
  float phi(const V3& x) const {
    const float d = sdf(local(x));
    return container ? -d : d;
  }
  V3 normalAt(const V3& x) const {
    const V3 l = local(x);
    const V3 q(std::fabs(l.x()) - half.x(), std::fabs(l.y()) - half.y(),
               std::fabs(l.z()) - half.z());
    V3 n = V3::Zero();
    if (q.x() > 0.0f || q.y() > 0.0f || q.z() > 0.0f) {
      for (int i = 0; i < 3; ++i) n[i] = q[i] > 0.0f ? std::copysign(q[i], l[i]) : 0.0f;
      n /= length(n);
    } else {
      int i = 0;
      if (q.y() > q[i]) i = 1;
      if (q.z() > q[i]) i = 2;
      n[i] = std::copysign(1.0f, l[i]);
    }
    if (container) n = -n;
    return mul(rotation, n);
  }
  bool entry(const V3& a, const V3& b, float tolerance, Entry& e) const {
    const float pa = phi(a), pb = phi(b);
    if (pa < -tolerance) {
      e.s = 0.0f;
      return true;
    }
    const V3 m = local(a), d = local(b) - m;
    if (container) {
      if (!(pb < -tolerance)) return false;  // convex: the path leaves it only there
      float exit = 1.0f;
      for (int i = 0; i < 3; ++i) {
        if (d[i] == 0.0f) continue;
        const float t = (std::copysign(half[i], d[i]) - m[i]) / d[i];
        exit = std::min(exit, t);
      }
      e.s = std::max(exit, 0.0f);
      return true;
    }
    // Slabs: the path is inside the box for s in (enter, leave).
    float enter = -1.0f, leave = 2.0f;
    for (int i = 0; i < 3; ++i) {
      if (d[i] == 0.0f) {
        if (!(std::fabs(m[i]) < half[i])) return false;
        continue;
      }
      float t0 = (-half[i] - m[i]) / d[i], t1 = (half[i] - m[i]) / d[i];
      if (t0 > t1) std::swap(t0, t1);
      enter = std::max(enter, t0);
      leave = std::min(leave, t1);
    }
    // A start on or within the margin of a face is not a contact unless the path goes deeper.
    const bool through = enter >= 0.0f && enter < leave && enter <= 1.0f;
    if (!(pb < -tolerance) && !through) return false;
    e.s = std::clamp(enter, 0.0f, 1.0f);
    return true;
  }
};

}  // namespace tickfx::collide
