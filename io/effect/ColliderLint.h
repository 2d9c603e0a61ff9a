// Internal to the effect linter (not installed): warnings about [[colliders]].
#pragma once

#include <vector>

#include "fields/ColliderSet.h"
#include "io/effect/Diagnostics.h"
#include "io/effect/EffectSettings.h"

namespace tickfx::io::detail {

// Appends to `out` the colliders' warnings (docs/effects.md, "Lint warnings"): a collider every
// start point of an emitter is inside; a level set whose voxel is coarser than the particles'
// radius; a moving level set that moves more than a voxel a tick; a level set that cannot be
// made (the builder's message: `tickfx run` stops at it); hits asked of an effect without
// colliders. `built`: the colliders the builder
// made from effect.colliders, or null to make them here.
void lintColliders(const EffectSettings& effect, const ColliderSet* built,
                   std::vector<Diagnostic>& out);

}  // namespace tickfx::io::detail
