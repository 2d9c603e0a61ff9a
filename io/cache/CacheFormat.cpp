#include "io/cache/CacheFormat.h"

namespace tickfx::io {

std::string_view cacheFormatName(CacheFormat format) {
  switch (format) {
    case CacheFormat::Csv:
      return "csv";
    case CacheFormat::Ply:
      return "ply";
    case CacheFormat::Vdb:
      return "vdb";
    case CacheFormat::Usda:
      return "usda";
  }
  return "csv";
}

std::optional<CacheFormat> cacheFormatFromName(std::string_view name) {
  for (const CacheFormat f : kCacheFormatList) {
    if (cacheFormatName(f) == name) return f;
  }
  return std::nullopt;
}

}  // namespace tickfx::io
