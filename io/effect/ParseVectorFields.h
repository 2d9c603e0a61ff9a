// Internal to the effect parser (not installed): [[forces]] entries of type "vector_field", a
// field read from a .vdb file (or a sequence of them) or baked from a formula, and the rule that
// keeps advection apart from accelerations.
#pragma once

#include <cstddef>
#include <vector>

#include "io/effect/EffectSettings.h"
#include "io/effect/TableReader.h"

namespace tickfx::io::detail {

// The keys of a vector field after its `type`, through `r`, into `f`: file (f.path resolved
// against the effect file's directory) or bake, grid, mode, scale, interpolation, outside, and
// the sequence keys (fps, first_frame, last_frame, frame_padding). A bake's grid is checked for
// size over all its frames (see measureBake).
void readVectorField(Context& cx, TableReader& r, VectorFieldSettings& f);

// Advection prescribes velocity: next to it, every acceleration (forces, a structure's springs)
// would be silently dropped, so an effect may not mix them (ForceSet would refuse too). Several
// advect fields are fine: their velocities add. Reports, at the `mode` of each advect field, the
// forces and structures it would ignore. `entries` holds the [[forces]] entry of each of
// effect.forces.
void checkAdvection(Context& cx, const EffectSettings& effect,
                    const std::vector<std::size_t>& entries);

}  // namespace tickfx::io::detail
