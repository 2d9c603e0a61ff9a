#include "io/cache/CacheFolder.h"

#include <algorithm>
#include <charconv>
#include <map>
#include <stdexcept>
#include <string>

#include "io/cache/CsvCache.h"
#include "io/cache/PlyCache.h"
#include "io/cache/VdbPointCache.h"

namespace tickfx::io {
namespace {

// Formats in the order a frame cached in several is read from.
constexpr const char* kExtensions[] = {".vdb", ".ply", ".csv"};

// The frame number of "frame_N.EXT", or -1 for any other name.
std::int64_t frameNumber(const std::string& stem) {
  const std::string prefix = "frame_";
  if (stem.rfind(prefix, 0) != 0 || stem.size() == prefix.size()) return -1;
  std::int64_t n = -1;
  const char* begin = stem.data() + prefix.size();
  const char* end = stem.data() + stem.size();
  const auto [at, ec] = std::from_chars(begin, end, n);
  return ec == std::errc() && at == end && n >= 0 ? n : -1;
}

}  // namespace

std::vector<CacheFrameFile> listCacheFrames(const std::filesystem::path& directory) {
  std::error_code error;
  if (!std::filesystem::is_directory(directory, error)) {
    throw std::runtime_error(directory.string() + ": error: not a folder of frame caches");
  }
  std::map<std::int64_t, std::pair<int, std::filesystem::path>> best;  // frame -> (rank, path)
  for (const auto& entry : std::filesystem::directory_iterator(directory, error)) {
    const std::string ext = entry.path().extension().string();
    const auto rank = std::find(std::begin(kExtensions), std::end(kExtensions), ext);
    if (rank == std::end(kExtensions) || !entry.is_regular_file(error)) continue;
    const std::int64_t frame = frameNumber(entry.path().stem().string());
    if (frame < 0) continue;
    const int r = static_cast<int>(rank - std::begin(kExtensions));
    const auto it = best.find(frame);
    if (it == best.end() || r < it->second.first) best[frame] = {r, entry.path()};
  }
  if (error) {
    throw std::runtime_error(directory.string() + ": error: cannot list the folder (" +
                             error.message() + ")");
  }
  if (best.empty()) {
    throw std::runtime_error(directory.string() +
                             ": error: no frame caches here (expected frame_0001.vdb, .ply or "
                             ".csv, as tickfx run writes them)");
  }
  std::vector<CacheFrameFile> files;
  for (const auto& [frame, found] : best) files.push_back({frame, found.second});
  return files;
}

FrameData readCacheFrame(const CacheFrameFile& file) {
  const std::string ext = file.path.extension().string();
  FrameData data = ext == ".vdb"   ? readVdbPointCache(file.path)
                   : ext == ".ply" ? readPlyCache(file.path)
                                   : readCsvCache(file.path);
  data.frame = file.frame;
  return data;
}

}  // namespace tickfx::io
