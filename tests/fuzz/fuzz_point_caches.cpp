// libFuzzer targets for the point cache readers that seed emitters from files: CSV, PLY and VDB
// points. The same source builds three targets, one reader each (TICKFX_FUZZ_READER). Any input
// must give a frame whose columns agree in length, or the reader's std::runtime_error.
#include <cstddef>
#include <cstdint>
#include <stdexcept>

#include "FuzzScratch.h"
#include "io/cache/CsvCache.h"
#include "io/cache/PlyCache.h"
#include "io/cache/VdbPointCache.h"

namespace {

tickfx::io::FrameData read(const std::filesystem::path& path) {
#if TICKFX_FUZZ_READER == 1
  return tickfx::io::readCsvCache(path);
#elif TICKFX_FUZZ_READER == 2
  return tickfx::io::readPlyCache(path);
#elif TICKFX_FUZZ_READER == 3
  return tickfx::io::readVdbPointCache(path);
#else
#error "TICKFX_FUZZ_READER must be 1 (CSV), 2 (PLY) or 3 (VDB points)"
#endif
}

constexpr const char* kScratchName = TICKFX_FUZZ_READER == 1   ? "frame.csv"
                                     : TICKFX_FUZZ_READER == 2 ? "frame.ply"
                                                               : "frame.vdb";

bool consistent(const tickfx::io::FrameData& f) {
  const auto n = static_cast<Eigen::Index>(f.size());
  for (const auto* c : {&f.position, &f.velocity}) {
    if (c->x.size() != n || c->y.size() != n || c->z.size() != n) return false;
  }
  for (const auto* c : {&f.age, &f.life, &f.mass}) {
    if (c->size() != n) return false;
  }
  if (f.attributes.size() != f.attributeNames.size()) return false;
  for (const auto& a : f.attributes) {
    if (a.size() != n) return false;
  }
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = tickfx::fuzz::writeScratch(kScratchName, data, size);
  try {
    if (!consistent(read(path))) __builtin_trap();
  } catch (const std::runtime_error&) {
  }
  return 0;
}
