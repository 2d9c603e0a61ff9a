// Frame caches as binary little-endian PLY point clouds (Houdini, Blender, MeshLab read them).
#pragma once

#include <filesystem>

#include "io/cache/FrameData.h"
#include "io/util/AtomicFile.h"

namespace tickfx::io {

/// Writes `frame` to `path` (atomically) as `element vertex` with float properties x y z vx vy vz
/// age life mass and the custom attributes, and `double id` (exact for ids below 2^53; PLY has no
/// 64-bit integer type). Colour and opacity take PLY's names: Cd_r, Cd_g, Cd_b and Alpha are the
/// float properties red, green, blue (linear RGB) and alpha; pscale keeps its name. Whole-number
/// attributes (isIntAttribute) are `int`. Comments carry the frame number and time.
void writePlyCache(const FrameData& frame, const std::filesystem::path& path,
                   Durability durability = Durability::Renamed);

/// Reads a file written by writePlyCache (binary little-endian with exactly those properties;
/// red, green, blue and alpha come back as Cd_r, Cd_g, Cd_b and Alpha).
/// Throws std::runtime_error naming the file on anything else or on a truncated body.
FrameData readPlyCache(const std::filesystem::path& path);

}  // namespace tickfx::io
