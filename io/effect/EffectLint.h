// Warnings about effects that are valid but will not move the way their author expects.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "fields/ColliderSet.h"
#include "fields/ForceSet.h"
#include "io/effect/Diagnostics.h"
#include "io/effect/EffectSettings.h"

namespace tickfx::io {

/// The largest ω·dt at which `integrator` keeps an undamped spring bounded, or nothing when no
/// step is small enough to keep its energy (explicit_euler gains energy at every ω·dt > 0):
///   semi_implicit_euler, position_verlet, velocity_verlet: 2 (symplectic; exact);
///   rk4: 2.785, the radius of its stability region on the real axis, its smallest (an undamped
///        spring alone would stay bounded up to 2√2 ≈ 2.83; damping moves it towards the axis);
///   midpoint: √2 ≈ 1.414 (tickfx's midpoint scheme; below it the energy decays every step).
std::optional<double> springStabilityLimit(std::string_view integrator);

/// How far above its mean n neighbours the lint allows a cluster's best-connected particle:
/// n + 3√n (the degrees spread about like a Poisson count). See structureStiffness.
inline constexpr double kClusterSpread = 3.0;

/// The lint's estimate of a structure's fastest vibration: ω = √(stiffness / m) with
/// `stiffness` = springFactor · k (k the structure's `stiffness`, m its `mass`):
///   - rope: 4k. A chain of springs k between masses m vibrates at most at ω = 2√(k/m) (the
///     zig-zag mode, neighbours moving against each other: each end pulls with 2k); exact for a
///     long rope.
///   - cloth: 4k(1 + shear_scale + bend_scale). Structural and shear springs give 4k(1 + shear)
///     in the cloth's zig-zag (along rows, in the plane); bend springs add at most 4k·bend (their
///     own zig-zag). An upper bound: ω is 4 % above the truth with the default scales.
///   - cluster: (n + 3√n)k, n = clusterNeighbours() the mean neighbour count; at least 4k (the
///     small chains and triangles of a sparse cluster) and at most count·k (the bound for
///     springs among count particles, reached when every pair is joined). A random network's
///     fastest vibration is led by its best-connected particles, whose degrees spread about the
///     mean like a Poisson count. Against the largest eigenvalue of clusters the core built
///     (10 to 1000 particles, link_radius from 0.1 to 2 times the radius) the true ω is 0.76 to
///     1.15 times this estimate (above 1 only for clusters of less than one neighbour on
///     average, whose few springs form chance pairs, chains and stars).
/// Springs' damping scales like their stiffness (c_eff = springFactor · c).
struct StructureStiffness {
  double springFactor = 4.0;
  double stiffness = 0.0;  // springFactor · k, N/m
  std::string formula;  // "4k", "4k(1 + shear_scale + bend_scale)", "(n + 3*sqrt(n))*k", "count*k"
  std::optional<double> neighbours;  // n, for a cluster
};
StructureStiffness structureStiffness(const StructureSettings& structure);

/// Checks a valid effect for mistakes a validator cannot call errors. Every warning names the
/// number that fixes it:
///   - a wind whose frequency f is at or above half the step rate aliases (the seed's 16 Hz wind
///     at 20 Hz is sampled as a 4 Hz wind that pushes the wrong way): a step_rate of at least
///     ⌊2f⌋ + 1 Hz;
///   - the anchor springs (ω = √(k/m), m the lightest emitter mass, dt = 1/step_rate) with ω·dt
///     at or past springStabilityLimit(): a step_rate of at least ⌊ω / limit⌋ + 1 Hz. Every
///     anchor spring pulls on every particle, so k and c are the stiffnesses and dampings of all
///     of them added up (two springs each under the limit can be past it together); the warning
///     is shown at the first one's stiffness and names the others;
///   - those springs under explicit_euler while damping < k·dt (they gain energy every step,
///     ×(1 + (k·dt − c)·dt/m)), or undamped under midpoint (they lose energy every step,
///     ×(1 − ω²dt²/2)): the step_rate that keeps the drift over the output's duration under 1 %,
///     and for explicit_euler the damping that stops the gain.
///   - the stiffest structure (largest ω, see structureStiffness, with every anchor spring's k
///     added to k_eff since anchors pull on structures too, and m the structure's mass) with ω·dt
///     at or past springStabilityLimit(): a step_rate of at least ⌊ω / limit⌋ + 1 Hz;
///   - under explicit_euler, that structure while its fastest vibration gains energy, i.e.
///     c_eff < k_eff·dt (×(1 + (k_eff·dt − c_eff)·dt/m) a step): the damping per spring that
///     stops the gain and the step_rate that keeps it under 1 % over the output. (Midpoint's
///     loss in a structure's fastest vibration is not warned about: it only damps the jitter.)
///   - a vector field whose file or grid cannot be loaded (the message VectorField gives,
///     naming file and grid; `tickfx run` stops at it), and, in modes drag and advect, a field
///     that carries particles more than a voxel a step: speed·dt > h, with speed the field's
///     largest |u| over all frames (times |scale| for advect) and h its voxel size, the CFL
///     condition of advection: a step_rate of at least ⌈speed / h⌉ Hz. Fields are loaded (or
///     baked) to know this, as the builder will load them.
///   - output fps and step rate that need more ticks a frame than max_ticks_per_frame allows
///     (⌈step_rate / fps⌉): what a real-time host advancing at that fps would drop. The fix:
///     that many ticks a frame, or a step_rate of at most ⌊max_ticks_per_frame · fps⌋ Hz.
/// An anchor spring's mass m is the lightest of the emitters' and the structures'.
/// Positions come from effect.sources (the value's line, else its table's header).
///
/// `built`: the forces buildForces() (or a ParticleSystem built from `effect`) made, in effect
/// order; their vector fields are then inspected instead of loaded again. Without it, fields are
/// loaded (or baked) here.
/// `colliders`: the colliders the builder made, in effect order (level sets are then not read
/// again); without them they are made here. Their warnings: see io/effect/ColliderLint.h.
std::vector<Diagnostic> lintEffect(const EffectSettings& effect, const ForceSet* built = nullptr,
                                   const ColliderSet* colliders = nullptr);

/// Of lintEffect()'s findings, the first that says a step grows without bound or adds energy every
/// step: the likely cause when a run's state stops being finite. nullptr when none says so.
const Diagnostic* instabilityWarning(const std::vector<Diagnostic>& lint);

}  // namespace tickfx::io
