// A folder of frame caches as `tickfx run` writes them (frame_0001.vdb, ...), read back.
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

#include "io/cache/FrameData.h"

namespace tickfx::io {

/// One frame's file in a cache folder.
struct CacheFrameFile {
  std::int64_t frame = 0;  // from the file's name
  std::filesystem::path path;
};

/// The frames of `directory`: files named frame_N.vdb, frame_N.ply or frame_N.csv (N whole,
/// from 0), in frame order. A frame cached in more than one format is read from one file only,
/// the first of vdb, ply, csv (the VDB cache keeps every attribute of the others). Other files
/// are not frames and are passed over. Throws std::runtime_error "DIR: error: ..." when
/// `directory` is not a folder or holds no frame.
std::vector<CacheFrameFile> listCacheFrames(const std::filesystem::path& directory);

/// Reads one frame's file by its extension (readVdbPointCache, readPlyCache or readCsvCache);
/// the frame number is the file's. Throws std::runtime_error naming the file.
FrameData readCacheFrame(const CacheFrameFile& file);

}  // namespace tickfx::io
