// Warnings about effects that are valid but will not move the way their author expects.
#pragma once

#include <optional>
#include <string_view>
#include <vector>

#include "io/Diagnostics.h"
#include "io/EffectSettings.h"

namespace tickfx::io {

/// The largest ω·dt at which `integrator` keeps an undamped spring bounded, or nothing when no
/// step is small enough to keep its energy (explicit_euler gains energy at every ω·dt > 0):
///   semi_implicit_euler, position_verlet, velocity_verlet: 2 (symplectic; exact);
///   rk4: 2.785, the radius of its stability region on the real axis, its smallest (an undamped
///        spring alone would stay bounded up to 2√2 ≈ 2.83; damping moves it towards the axis);
///   midpoint: √2 ≈ 1.414 (tickfx's midpoint scheme; below it the energy decays every step).
std::optional<double> springStabilityLimit(std::string_view integrator);

/// Checks a valid effect for mistakes a validator cannot call errors. Every warning names the
/// number that fixes it:
///   - a wind whose frequency f is at or above half the step rate aliases (the seed's 16 Hz wind
///     at 20 Hz is sampled as a 4 Hz wind that pushes the wrong way): a step_rate of at least
///     ⌊2f⌋ + 1 Hz;
///   - an anchor spring (ω = √(k/m), m the lightest emitter mass, dt = 1/step_rate) with ω·dt at
///     or past springStabilityLimit(): a step_rate of at least ⌊ω / limit⌋ + 1 Hz;
///   - an anchor spring under explicit_euler while damping < k·dt (it gains energy every step,
///     ×(1 + (k·dt − c)·dt/m)), or undamped under midpoint (it loses energy every step,
///     ×(1 − ω²dt²/2)): the step_rate that keeps the drift over the output's duration under 1 %,
///     and for explicit_euler the damping that stops the gain.
/// Positions come from effect.sources (the value's line, else its table's header).
std::vector<Diagnostic> lintEffect(const EffectSettings& effect);

}  // namespace tickfx::io
