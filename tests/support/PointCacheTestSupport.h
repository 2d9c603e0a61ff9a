// What the tests of VDB point caches (io/cache/VdbPointCache) share: the smallest cache, and the
// one damage to it that OpenVDB 10 asserted on.
#pragma once

#include <cstddef>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "io/cache/FrameData.h"
#include "io/cache/VdbCacheOptions.h"
#include "tests/support/FileBytes.h"

namespace tickfx::test {

/// One particle, id 7, at (0.5, 1.5, 2.5) m moving at (1, 1, 1) m/s, age 0 s, life 5 s, mass
/// 1 kg: every standard column set, no custom attribute.
inline io::FrameData onePointFrame() {
  io::FrameData one;
  one.resize(1, {});
  one.id = {7};
  for (int c = 0; c < 3; ++c) {
    one.position[c][0] = 0.5f + static_cast<float>(c);
    one.velocity[c][0] = 1.0f;
  }
  one.age[0] = 0.0f;
  one.life[0] = 5.0f;
  one.mass[0] = 1.0f;
  return one;
}

/// OpenVDB writes attribute arrays in pages (a page header, then each array's bytes) only when it
/// compresses them: the one layout whose damage OpenVDB 10 asserted on.
inline constexpr io::VdbCacheOptions kPagedArrays{io::VdbCacheOptions::Compression::Blosc};

/// In the cache `file` of onePointFrame() written with kPagedArrays, adds one to the byte count of
/// its first attribute array (P: 6 + 12 bytes, a little-endian uint64, the first 8 bytes of the
/// file that read 18), so that the array claims 13 bytes of data where 12 are there: OpenVDB 10's
/// paged stream asserted on it (mByteIndex <= mUncompressedBytes). Returns the count's offset in
/// the file, the byte a refusal names, or std::string::npos (and leaves the file alone) without
/// one.
inline std::size_t overstateFirstAttributeArray(const std::filesystem::path& file) {
  std::string bytes = fileBytes(file);
  const std::string count{"\x12\0\0\0\0\0\0\0", 8};
  const std::size_t at = bytes.find(count);
  if (at == std::string::npos) return at;
  bytes[at] = '\x13';
  std::ofstream(file, std::ios::binary) << bytes;
  return at;
}

}  // namespace tickfx::test
