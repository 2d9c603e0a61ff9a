#include "io/cache/FrameCaches.h"

#include <cinttypes>
#include <cstdio>
#include <string>

#include "io/cache/CsvCache.h"
#include "io/cache/PlyCache.h"
#include "io/cache/UsdaPointsWriter.h"

namespace tickfx::io {

std::filesystem::path cacheFilePath(const std::filesystem::path& directory, std::int64_t frame,
                                    std::string_view extension) {
  char name[32];
  std::snprintf(name, sizeof name, "frame_%04" PRId64 ".", frame);
  return directory / (name + std::string(extension));
}

void writeFrameCaches(const FrameData& frame, const CacheTargets& targets) {
  for (const CacheFormat format : targets.formats) {
    if (format == CacheFormat::Usda) {
      if (targets.usda != nullptr) targets.usda->write(frame);
      continue;
    }
    const std::filesystem::path path =
        cacheFilePath(targets.directory, frame.frame, cacheFormatName(format));
    switch (format) {
      case CacheFormat::Csv:
        writeCsvCache(frame, path, targets.durability);
        break;
      case CacheFormat::Ply:
        writePlyCache(frame, path, targets.durability);
        break;
      case CacheFormat::Vdb:
        writeVdbPointCache(frame, targets.vdbMetadata, path, targets.vdbOptions,
                           targets.durability);
        break;
      case CacheFormat::Usda:
        break;
    }
  }
}

}  // namespace tickfx::io
