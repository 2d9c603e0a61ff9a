// The kinds of per-frame cache a run writes.
#pragma once

#include <optional>
#include <string_view>

namespace tickfx::io {

enum class CacheFormat { Csv, Ply, Vdb };
/// Every cache format, in the order names are listed to users.
inline constexpr CacheFormat kCacheFormatList[] = {CacheFormat::Csv, CacheFormat::Ply,
                                                   CacheFormat::Vdb};
/// "csv", "ply" or "vdb": the name in effect files and on the command line, and the extension.
std::string_view cacheFormatName(CacheFormat format);
/// The format called `name` (as cacheFormatName gives it), or nothing.
std::optional<CacheFormat> cacheFormatFromName(std::string_view name);

}  // namespace tickfx::io
