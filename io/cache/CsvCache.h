// Frame caches as CSV text: one row a particle, readable by a spreadsheet or a script.
#pragma once

#include <filesystem>

#include "io/cache/FrameData.h"
#include "io/util/AtomicFile.h"

namespace tickfx::io {

/// Writes `frame` to `path` (atomically): a header `id,px,py,pz,vx,vy,vz,age,life,mass` followed
/// by the custom attributes' names, then one row a particle in id order. Floats are printed in
/// the shortest form that reads back to the same float bits (std::to_chars: `0.1`, `-9.81`,
/// `1e+30`); a non-finite value (an effect run with simulation.nonfinite = "keep") as `inf`,
/// `-inf` or `nan` (any NaN, whatever its sign or payload). Rows are formatted in parallel
/// blocks and written in order: the bytes are the same on any thread count.
void writeCsvCache(const FrameData& frame, const std::filesystem::path& path,
                   Durability durability = Durability::Renamed);

/// Reads a file written by writeCsvCache. Throws std::runtime_error naming the file and line on
/// anything malformed.
FrameData readCsvCache(const std::filesystem::path& path);

}  // namespace tickfx::io
