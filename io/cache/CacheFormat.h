// The kinds of per-frame cache a run writes.
#pragma once

#include <optional>
#include <string_view>

namespace tickfx::io {

/// Csv, Ply and Vdb write a file a frame; Usda writes one USD layer a run, a time sample a frame
/// (UsdaPointsWriter).
enum class CacheFormat { Csv, Ply, Vdb, Usda };
/// Every cache format, in the order names are listed to users.
inline constexpr CacheFormat kCacheFormatList[] = {CacheFormat::Csv, CacheFormat::Ply,
                                                   CacheFormat::Vdb, CacheFormat::Usda};
/// "csv", "ply", "vdb" or "usda": the name in effect files and on the command line, and the
/// extension.
std::string_view cacheFormatName(CacheFormat format);
/// The format called `name` (as cacheFormatName gives it), or nothing.
std::optional<CacheFormat> cacheFormatFromName(std::string_view name);

}  // namespace tickfx::io
