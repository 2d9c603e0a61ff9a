// A scheme's row kernel run on bounds of its rows' magnitudes instead of on rows: what
// Integrator::boundTick carries a StateBound through, by the very operations the tick runs.
#pragma once

#include <cmath>
#include <type_traits>

#include "integrators/CheckedRows.h"
#include "integrators/UniformAndDragRows.h"
#include "particles/StateBound.h"

namespace tickfx {

/// The value of a Lane in a row kernel run on bounds instead of rows (boundTickUnderForms): an
/// upper bound of the magnitude of that value in any row whose inputs are within their bounds.
/// Sums and differences add magnitudes, products multiply them, each widened by 2⁻²⁰ for the
/// float operation's rounding (at most 2⁻²⁴ relative; a subnormal result may round up by 2⁻¹⁴⁹
/// more, which the factor 4 between StateBound::kLimit and FLT_MAX absorbs) and this double
/// one's. A result past kLimit becomes +∞, so that the float operation it stands for is never
/// assumed not to overflow. The kernels use no division, so Magnitude has none: one added to a
/// kernel does not compile until it is given a sound bound here.
struct Magnitude {
  double m = 0.0;

  static Magnitude of(double value) {
    constexpr double kWiden = 1.0 + 0x1p-20;
    const double widened = value * kWiden;
    return {widened <= StateBound::kLimit ? widened : INFINITY};
  }
};

inline Magnitude operator+(Magnitude a, Magnitude b) { return Magnitude::of(a.m + b.m); }
inline Magnitude operator-(Magnitude a, Magnitude b) { return Magnitude::of(a.m + b.m); }
inline Magnitude operator*(Magnitude a, Magnitude b) { return Magnitude::of(a.m * b.m); }
inline Magnitude operator+(Magnitude a, float b) { return a + Magnitude{std::fabs(b)}; }
inline Magnitude operator+(float a, Magnitude b) { return Magnitude{std::fabs(a)} + b; }
inline Magnitude operator-(Magnitude a, float b) { return a - Magnitude{std::fabs(b)}; }
inline Magnitude operator-(float a, Magnitude b) { return Magnitude{std::fabs(a)} - b; }
inline Magnitude operator*(Magnitude a, float b) { return a * Magnitude{std::fabs(b)}; }
inline Magnitude operator*(float a, Magnitude b) { return Magnitude{std::fabs(a)} * b; }

template <>
inline Magnitude broadcast<Magnitude>(float value) {
  return {std::fabs(value)};
}

/// The RowsAt of a kernel run on bounds: the columns it is handed are the slots of `bound` (one
/// float each, never read), a load is the slot's bound and a store replaces it (flushTiny only
/// shrinks a magnitude).
struct BoundsAt {
  const float* slots;
  double* bound;

  Magnitude load(const float* column) const { return {bound[column - slots]}; }
  void store(float* column, Magnitude value) const { bound[column - slots] = value.m; }
  void copy(float* column, Magnitude value) const { store(column, value); }
};

/// Where a scheme's one-pass kernel keeps StateBound::extra: nowhere, in the previous position
/// (position Verlet), or in a fourth column after it (velocity Verlet's acceleration).
enum class ExtraColumn { kNone, kPrevious, kFourth };

/// The bound after one tick of a scheme's one pass (runOnePass: a kernel over the position, the
/// velocity, the previous position and, for kFourth, one more column) under `forms`, from
/// `start`: the kernel `kernelFor` gives for each component, run on bounds. Each bound is at least
/// the one it starts from, so that a row spawned later in a frame, within `start`, is within the
/// bounds of every tick it steps.
template <class KernelFor>
StateBound boundTickUnderForms(const TickForms& forms, const KernelFor& kernelFor,
                               const StateBound& start, ExtraColumn extra = ExtraColumn::kNone) {
  StateBound out = start;
  for (int c = 0; c < 3; ++c) {
    withFormAccelerations(forms, c, [&](const auto& accelerations) {
      float slots[4] = {};
      double bound[4] = {start.position, start.velocity,
                         extra == ExtraColumn::kPrevious ? start.extra : 0.0, start.extra};
      const BoundsAt at{slots, bound};
      const auto kernel = kernelFor(accelerations);
      if constexpr (std::is_invocable_v<decltype(kernel), BoundsAt, float*, float*, float*>) {
        kernel(at, &slots[0], &slots[1], &slots[2]);
      } else {
        kernel(at, &slots[0], &slots[1], &slots[2], &slots[3]);
      }
      const double after = extra == ExtraColumn::kPrevious ? bound[2]
                           : extra == ExtraColumn::kFourth ? bound[3]
                                                           : 0.0;
      out = wider(out, StateBound{bound[0], bound[1], after});
      return 0;
    });
  }
  return out;
}

/// The bound of `bound.extra` widened by what `start(accelerations, position, velocity)` (a
/// scheme's start of a spawned row's third column, on Magnitude values) makes under `forms` from
/// rows within bound.position and bound.velocity.
template <class Start>
void boundSpawnedUnderForms(const TickForms& forms, const Start& start, StateBound& bound) {
  for (int c = 0; c < 3; ++c) {
    withFormAccelerations(forms, c, [&](const auto& accelerations) {
      const Magnitude made =
          start(accelerations, Magnitude{bound.position}, Magnitude{bound.velocity});
      bound.extra = wider(bound.extra, made.m);
      return 0;
    });
  }
}

}  // namespace tickfx
