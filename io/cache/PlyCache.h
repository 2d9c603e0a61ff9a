// Frame caches as binary little-endian PLY point clouds (Houdini, Blender, MeshLab read them).
#pragma once

#include <filesystem>

#include "io/cache/FrameData.h"
#include "io/util/AtomicFile.h"

namespace tickfx::io {

/// Writes `frame` to `path` (atomically) as `element vertex` with float properties x y z vx vy vz
/// age life mass and the custom attributes, and `double id` (exact for ids below 2^53; PLY has no
/// 64-bit integer type). Comments carry the frame number and time.
void writePlyCache(const FrameData& frame, const std::filesystem::path& path,
                   Durability durability = Durability::Renamed);

/// Reads a file written by writePlyCache (binary little-endian with exactly those properties).
/// Throws std::runtime_error naming the file on anything else or on a truncated body.
FrameData readPlyCache(const std::filesystem::path& path);

}  // namespace tickfx::io
