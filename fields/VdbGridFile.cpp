#include "fields/VdbGridFile.h"

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace tickfx {

std::string vdbGridLabel(const std::string& path, const std::string& grid) {
  return path + ": grid '" + grid + "'";
}

namespace {

/// Checks, before OpenVDB reads any grid data, that every grid of the file ends within the file.
/// OpenVDB 10 reads a file cut inside its grid data with garbage sizes (it may hang or fail at
/// random), so the byte ranges in the grid descriptors are compared with the file size first.
/// Layout (io::Archive::readHeader, MetaMap::readMeta, GridDescriptor::read): magic (8),
/// format version (4), library major and minor (4 + 4), has-offsets flag (1), [compression flag
/// (1) before format 222], UUID (36); file metadata: count (4), then per entry name and type
/// strings and a byte-counted value; grid count (4); per grid: name, type, [instance parent
/// from format 216] strings, then grid, block and end offsets (8 each), the next descriptor
/// at the end offset. Strings are a 4-byte length and the bytes.
void checkExtent(const std::string& path, const std::string& name) {
  std::ifstream is(path, std::ios::binary);
  std::error_code ec;
  const auto size = static_cast<std::int64_t>(std::filesystem::file_size(path, ec));
  auto fail = [&](const std::string& what) {
    throw std::runtime_error(vdbGridLabel(path, name) + ": cannot read the grid (" + what + ")");
  };
  auto u32 = [&]() {
    std::uint32_t v = 0;
    if (!is.read(reinterpret_cast<char*>(&v), sizeof v)) fail("the file is truncated");
    return v;
  };
  auto i64 = [&]() {
    std::int64_t v = 0;
    if (!is.read(reinterpret_cast<char*>(&v), sizeof v)) fail("the file is truncated");
    return v;
  };
  auto skip = [&](std::int64_t bytes) {
    if (bytes < 0 || static_cast<std::int64_t>(is.tellg()) + bytes > size) {
      fail("the file is truncated");
    }
    is.seekg(bytes, std::ios::cur);
  };
  auto skipString = [&]() { skip(u32()); };
  i64();  // magic (checked by OpenVDB already)
  const std::uint32_t version = u32();
  u32();
  u32();
  char hasOffsets = 0;
  if (!is.read(&hasOffsets, 1)) fail("the file is truncated");
  if (!hasOffsets) return;  // nothing to check against
  if (version < 222) skip(1);
  skip(36);
  const std::uint32_t metadata = u32();
  for (std::uint32_t i = 0; i < metadata; ++i) {
    skipString();
    skipString();
    skip(u32());
  }
  const std::uint32_t grids = u32();
  for (std::uint32_t i = 0; i < grids; ++i) {
    skipString();
    skipString();
    if (version >= 216) skipString();
    const std::int64_t gridPos = i64(), blockPos = i64(), endPos = i64();
    if (!(0 < gridPos && gridPos <= blockPos && blockPos <= endPos) || endPos > size) {
      fail("the file is truncated: a grid ends at byte " + std::to_string(endPos) + " of " +
           std::to_string(size));
    }
    is.seekg(endPos);
  }
}

}  // namespace

openvdb::GridBase::Ptr readVdbGrid(const std::string& path, const std::string& name) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw std::runtime_error(vdbGridLabel(path, name) + ": no such file");
  }
  openvdb::initialize();
  openvdb::io::File file(path);
  try {
    file.open(/*delayLoad=*/false);
  } catch (const std::exception& e) {
    throw std::runtime_error(vdbGridLabel(path, name) + ": cannot open the file as OpenVDB (" +
                             e.what() + ")");
  }
  openvdb::GridBase::Ptr grid;
  try {
    checkExtent(path, name);
    if (!file.hasGrid(name)) {
      std::string names;
      for (auto it = file.beginName(); it != file.endName(); ++it) {
        names += (names.empty() ? "" : ", ") + it.gridName();
      }
      file.close();
      throw std::runtime_error(vdbGridLabel(path, name) + ": no such grid (" +
                               (names.empty()
                                    ? std::string("the file holds no grids: empty or truncated")
                                    : "the file has: " + names) +
                               ")");
    }
    grid = file.readGrid(name);
    file.close();
  } catch (const std::runtime_error&) {
    throw;
  } catch (const std::exception& e) {
    throw std::runtime_error(vdbGridLabel(path, name) + ": cannot read the grid (" + e.what() +
                             ")");
  }
  if (!grid) throw std::runtime_error(vdbGridLabel(path, name) + ": cannot read the grid");
  return grid;
}

}  // namespace tickfx
