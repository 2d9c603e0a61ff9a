// Which rows' starting positions a block's collisions can do without: a span along one axis
// outside which no collider's screen flags a path (ColliderSet::startsSpan()), and the mask of
// the groups of rows whose starts a step wrote on every axis.
#pragma once

#include <cstddef>
#include <cstdint>

namespace tickfx {

/// A path whose two ends lie both below `lo` or both above `hi` on `axis` (0 x, 1 y, 2 z) meets
/// no collider's screen, whatever its other coordinates; axis −1: no such span. A NaN end is in
/// the span (its comparisons are false).
struct StartsSpan {
  /// The rows a bit of a StepRows::written mask stands for.
  static constexpr std::size_t kGroupRows = 128;

  int axis = -1;
  float lo = 0.0f;
  float hi = 0.0f;

  bool any() const { return axis >= 0; }
  /// 1 when the path a → b (its coordinates on `axis`) may meet a screen, else 0: no branch.
  int reaches(float a, float b) const {
    return 1 - ((static_cast<int>(a < lo) & static_cast<int>(b < lo)) |
                (static_cast<int>(a > hi) & static_cast<int>(b > hi)));
  }
};

}  // namespace tickfx
