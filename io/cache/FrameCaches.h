// The cache files of one frame, in every format a run writes.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string_view>
#include <vector>

#include "io/cache/CacheFormat.h"
#include "io/cache/FrameData.h"
#include "io/cache/VdbPointCache.h"
#include "io/util/AtomicFile.h"

namespace tickfx::io {
class UsdaPointsWriter;
}

namespace tickfx::io {

/// Where and how a run writes its per-frame caches.
struct CacheTargets {
  std::filesystem::path directory;
  std::vector<CacheFormat> formats;  // written in this order; empty: nothing
  VdbCacheMetadata vdbMetadata;
  VdbCacheOptions vdbOptions;
  Durability durability = Durability::Renamed;
  /// The run's USD layer, for CacheFormat::Usda (not owned; null: that format is skipped).
  UsdaPointsWriter* usda = nullptr;
};

/// DIRECTORY/frame_0001.EXTENSION (at least four digits).
std::filesystem::path cacheFilePath(const std::filesystem::path& directory, std::int64_t frame,
                                    std::string_view extension);

/// Writes `frame`'s file in each of targets.formats, in order, each atomically, and appends it to
/// targets.usda for CacheFormat::Usda (the layer is written whole when the run finishes). Throws
/// WriteError at the first file that cannot be written (the files before it stay, whole).
void writeFrameCaches(const FrameData& frame, const CacheTargets& targets);

}  // namespace tickfx::io
