// The state at the end of a run as text, for comparing runs and checking against analytics.
#pragma once

#include <filesystem>

#include "io/cache/FrameData.h"

namespace tickfx::io {

/// Writes the rows of `frame` to `path` (atomically) as CSV with the header
/// `id,px,py,pz,vx,vy,vz,age` and %.9g floats: the state at the frame's time (the tick's own
/// state when that time falls on a tick).
void writeStateDump(const FrameData& frame, const std::filesystem::path& path);

}  // namespace tickfx::io
