// Frame caches as CSV text: one row a particle, readable by a spreadsheet or a script.
#pragma once

#include <filesystem>

#include "io/FrameData.h"

namespace tickfx::io {

/// Writes `frame` to `path` (atomically): a header `id,px,py,pz,vx,vy,vz,age,life,mass` followed
/// by the custom attributes' names, then one row a particle in id order. Floats are printed with
/// %.9g, which reads back to the same float bits; a non-finite value (an effect run with
/// simulation.nonfinite = "keep") as `inf`, `-inf` or `nan` (any NaN, whatever its sign or payload).
void writeCsvCache(const FrameData& frame, const std::filesystem::path& path);

/// Reads a file written by writeCsvCache. Throws std::runtime_error naming the file and line on
/// anything malformed.
FrameData readCsvCache(const std::filesystem::path& path);

}  // namespace tickfx::io
