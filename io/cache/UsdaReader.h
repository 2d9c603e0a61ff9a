// Reading a .usda layer of points back: a parser of USD's text grammar, written apart from the
// writer (UsdaPointsWriter) so that each checks the other.
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

#include "io/cache/FrameData.h"

namespace tickfx::io {

/// Frame `frame` (a time code) of the first Points prim of the .usda layer at `path`, as
/// UsdaPointsWriter maps a frame to attributes (points, velocities, ids, widths / 2 as pscale,
/// primvars:displayColor as Cd, primvars:displayOpacity as Alpha, primvars:age, life, mass, and
/// every other primvars:NAME). The parser reads USD's text grammar: the `#usda 1.0` header,
/// comments, any whitespace, layer, prim and attribute metadata, defaults and time samples, and
/// nested prims (skipped). Throws std::runtime_error "PATH: what" for a file that is not such a
/// layer, is cut short, or has no sample at `frame`.
FrameData readUsdaFrame(const std::filesystem::path& path, std::int64_t frame);

/// The time codes at which the layer at `path` holds samples of `points`, rising.
std::vector<std::int64_t> usdaFrames(const std::filesystem::path& path);

}  // namespace tickfx::io
