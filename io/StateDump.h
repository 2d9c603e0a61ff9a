// The raw state of the last tick as text, for comparing runs and checking against analytics.
#pragma once

#include <filesystem>

#include "particles/ParticlePool.h"

namespace tickfx::io {

/// Writes rows [0, pool.size()) of `pool` to `path` (atomically) as CSV with the header
/// `id,px,py,pz,vx,vy,vz,age` and %.9g floats: the state after the last completed tick, not
/// interpolated.
void writeStateDump(const ParticlePool& pool, const std::filesystem::path& path);

}  // namespace tickfx::io
