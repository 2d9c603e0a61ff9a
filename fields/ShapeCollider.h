// Internal to the colliders (not installed): a collider made of a shape (ColliderShapes.h, or a
// level set), the per-particle work written once for every shape as a template.
#pragma once

#include <algorithm>
#include <cmath>

#include "fields/Collider.h"
#include "fields/ColliderShapes.h"
#include "fields/ContactRows.h"

namespace tickfx::collide {

// `x` (world) in the rest frame of a collider at `pose`, and back.
inline V3 toRest(const ColliderPose& pose, const V3& x) {
  return mulTransposed(pose.rotation, x - pose.pivot - pose.translation) + pose.pivot;
}
inline V3 toWorld(const ColliderPose& pose, const V3& x) {
  return mul(pose.rotation, x - pose.pivot) + pose.pivot + pose.translation;
}

// A contact is placed where phi >= 0: from a point on the path (which rounding may leave a hair
// inside), along the surface normal by the depth and 4 ulps more, at most four times.
template <class Shape>
inline V3 settle(const Shape& shape, V3 x) {
  for (int k = 0; k < 4; ++k) {
    const float depth = shape.phi(x);
    if (depth >= 0.0f) break;
    const float ulps = std::max(1.0f, collide::maxAbs(x)) * 0x1p-21f;  // exact: a power of 2
    x = x + shape.normalAt(x) * (ulps - depth);
  }
  return x;
}

template <class Shape>
class ShapeCollider final : public Collider {
 public:
  ShapeCollider(const ColliderSettings& settings, const Shape& shape)
      : Collider(settings), shape_(shape) {}

  bool firstContact(const V3& a, float fromFraction, const V3& b, Contact& out) const override {
    return contactOf(a, fromFraction, b, out);
  }

  std::uint64_t contactRows(const RowsJob& job) const override {
    struct Alone {
      const ShapeCollider* self;
      const Collider* first(const V3& a, float from, const V3& b, Contact& out) const {
        return self->contactOf(a, from, b, out) ? self : nullptr;
      }
      V3 respond(const Collider& /*hit: self*/, const Contact& c, const V3& v) const {
        return respondWith(self->settings_.response, self->restitution_, self->friction_, c, v);
      }
    };
    return collide::contactRows(job, Alone{this});
  }

  const Shape& shape() const { return shape_; }

  float restClearance(const V3& rest) const override { return shape_.phi(rest); }

  void screen(const float* const a[3], const float* const b[3], std::size_t n,
              std::uint8_t* flags) const override {
    // The rest-frame points as firstContact() computes them from the tick's start: the same
    // expressions, so the same bits.
    if (!tick_.moving) {
      // Still: a loop over the columns the compiler vectorises, where the shape has one.
      if constexpr (kStillScreen == StillScreen::kColumns) {
        shape_.screenColumns(a, b, n, flags);
        return;
      } else if constexpr (kStillScreen == StillScreen::kBox) {
        V3 lo, hi;
        if (shape_.screenBox(lo, hi)) {
          screenBoxColumns(a, b, n, lo, hi, flags);
          return;
        }
      }
      for (std::size_t i = 0; i < n; ++i) {
        const V3 ra(a[0][i], a[1][i], a[2][i]), rb(b[0][i], b[1][i], b[2][i]);
        if (shape_.mayTouch(ra, rb)) flags[i] = 1;
      }
      return;
    }
    for (std::size_t i = 0; i < n; ++i) {
      const V3 ra = toRest(tick_.start, V3(a[0][i], a[1][i], a[2][i]));
      const V3 rb = toRest(tick_.end, V3(b[0][i], b[1][i], b[2][i]));
      if (shape_.mayTouch(ra, rb)) flags[i] = 1;
    }
  }

  // The bound of the screen above along `axis`: the still shape's own, where it screens its own
  // way (screenColumns), else its screening box's.
  bool screenSpan(int axis, float& lo, float& hi) const override {
    if (tick_.moving) return false;
    if constexpr (kStillScreen == StillScreen::kColumns) {
      if constexpr (requires { shape_.screenSpan(axis, lo, hi); }) {
        return shape_.screenSpan(axis, lo, hi);
      } else {
        return false;
      }
    } else if constexpr (kStillScreen == StillScreen::kBox) {
      V3 below, above;
      if (!shape_.screenBox(below, above)) return false;
      lo = below[axis];
      hi = above[axis];
      return true;
    }
    return false;
  }

 private:
  // How screen() screens a still shape's paths, which screenSpan() must bound: the shape's own
  // loop over the columns, its screening box's, or mayTouch() row by row.
  enum class StillScreen { kColumns, kBox, kRows };
  static constexpr StillScreen kStillScreen = [] {
    if constexpr (requires(const Shape& s) { s.screenColumns(nullptr, nullptr, 0, nullptr); }) {
      return StillScreen::kColumns;
    } else if constexpr (requires(const Shape& s, V3& v) { s.screenBox(v, v); }) {
      return StillScreen::kBox;
    } else {
      return StillScreen::kRows;
    }
  }();

  // firstContact(), inline for contactRows().
  [[gnu::always_inline]] bool contactOf(const V3& a, float fromFraction, const V3& b,
                                        Contact& out) const {
    V3 ra = a, rb = b;
    ColliderPose from;
    if (tick_.moving) {
      from = tick_.at(fromFraction);
      ra = toRest(from, a);
      rb = toRest(tick_.end, b);
    }
    const float tolerance = margin(std::max(collide::maxAbs(ra), collide::maxAbs(rb)));
    collide::Entry e;
    if (!shape_.entry(ra, rb, tolerance, e)) return false;
    const V3 point = settle(shape_, ra + (rb - ra) * e.s);
    V3 normal = shape_.normalAt(point);
    if (e.slope < 0.0f) normal = collide::facingPath(normal, rb - ra, e.slope);
    out.fraction = fromFraction + e.s * (1.0f - fromFraction);
    out.restPoint = point;
    if (!tick_.moving) {
      out.point = point;
      out.normal = normal;
      out.surfaceVelocity = V3::Zero();
      return true;
    }
    const ColliderPose at = tick_.at(out.fraction);
    out.point = toWorld(at, point);
    out.normal = collide::mul(at.rotation, normal);
    out.surfaceVelocity = tick_.surfaceVelocity(out.point, out.fraction);
    return true;
  }

  Shape shape_;
};

}  // namespace tickfx::collide
