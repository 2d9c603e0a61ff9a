#include "fields/vdb/VdbFileCheck.h"

#include <openvdb/io/DelayedLoadMetadata.h>
#include <openvdb/io/GridDescriptor.h>
#include <openvdb/openvdb.h>
#include <openvdb/points/PointDataGrid.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "fields/vdb/VdbCheckReader.h"
#include "fields/vdb/VdbPointsCheck.h"
#include "fields/vdb/VdbTreeCheck.h"

namespace tickfx::vdbcheck {
namespace {

// File formats (OPENVDB_FILE_VERSION_*): per-grid compression and mask-compressed node values
// from 222, multi-pass PointDataGrids from 224, which OpenVDB 10 writes.
constexpr std::uint32_t kOldestFormat = 222;
constexpr std::uint32_t kPointsFormat = 224;
constexpr std::uint32_t kNewestFormat = 224;

/// io::DelayedLoadMetadata::readValue (the "file_delayed_load" OpenVDB 6.2 and later write).
void checkDelayedLoad(Cursor& in, std::uint32_t numBytes, std::uint64_t leafBound) {
  // io::DelayedLoadMetadata::readValue: nothing for 0 bytes; a leaf count; per-leaf mask bytes and
  // compressed sizes, each raw or a blosc block; unknown bytes up to numBytes skipped.
  if (numBytes == 0) return;
  const std::size_t start = in.pos();
  const auto count = in.get<std::uint32_t>();
  if (count > leafBound) {
    in.corrupt(start, "delayed-load metadata for " + std::to_string(count) +
                          " leaves, more than the grid can hold");
  }
  for (const std::uint64_t itemSize : {std::uint64_t{1}, std::uint64_t{8}}) {
    const std::size_t at = in.pos();
    const auto bytes = in.get<std::uint32_t>();
    if (itemSize == 8 && bytes == std::numeric_limits<std::uint32_t>::max()) break;  // no sizes
    if (bytes > 0) {
      const char* block = in.take(bytes);
      checkBlosc(in, at + 4, block, bytes, count * itemSize, /*padded=*/true);
    } else {
      in.take(count * itemSize);
    }
  }
  const std::uint64_t total = in.pos() - start;
  if (total > numBytes) {
    in.corrupt(start, "delayed-load metadata of " + std::to_string(total) + " bytes where " +
                          std::to_string(numBytes) + " are declared");
  }
  in.take(numBytes - total);
}

}  // namespace

MetadataFound checkMetadata(Cursor& in, std::uint64_t leafBound) {
  MetadataFound found;
  const auto count = in.get<std::uint32_t>();
  std::set<std::string> names;
  for (std::uint32_t i = 0; i < count; ++i) {
    const std::size_t at = in.pos();
    const std::string name = in.string();
    const std::string type = in.string();
    const auto size = in.get<std::uint32_t>();
    if (name.empty() || !names.insert(name).second) {
      in.corrupt(at, "metadata named \"" + name + "\" (expected unique, non-empty names)");
    }
    if (type == openvdb::io::DelayedLoadMetadata::staticTypeName()) {
      checkDelayedLoad(in, size, leafBound);
      continue;
    }
    if (type == openvdb::StringMetadata::staticTypeName() ||
        !openvdb::Metadata::isRegisteredType(type)) {
      in.take(size);  // a string's bytes, or an unknown type's raw bytes
      continue;
    }
    const openvdb::Index32 expected = openvdb::Metadata::createMetadata(type)->size();
    if (size != expected) {
      in.corrupt(at, "metadata \"" + name + "\" of type " + type + " in " + std::to_string(size) +
                         " bytes (expected " + std::to_string(expected) + ")");
    }
    const char* value = in.take(size);
    const bool isBool = type == openvdb::BoolMetadata::staticTypeName();
    if (isBool && static_cast<unsigned char>(value[0]) > 1) {
      in.corrupt(at, "metadata \"" + name + "\" is a bool that is neither 0 nor 1");
    }
    if (name == openvdb::GridBase::META_SAVE_HALF_FLOAT) {
      if (!isBool) in.corrupt(at, "metadata \"" + name + "\" of type " + type + " (expected bool)");
      found.halfFloat = value[0] != 0;
    }
  }
  return found;
}

namespace {

/// math::Transform::read: a map type and its values (every one a finite double).
void checkTransform(Cursor& in) {
  static const std::map<std::string, std::size_t> kLinearMapDoubles = {
      {openvdb::math::AffineMap::mapType(), 16},
      {openvdb::math::UnitaryMap::mapType(), 16},
      {openvdb::math::ScaleMap::mapType(), 15},
      {openvdb::math::UniformScaleMap::mapType(), 15},
      {openvdb::math::TranslationMap::mapType(), 3},
      {openvdb::math::ScaleTranslateMap::mapType(), 18},
      {openvdb::math::UniformScaleTranslateMap::mapType(), 18},
  };
  auto doubles = [&](std::size_t n, std::size_t at) {
    for (std::size_t i = 0; i < n; ++i) {
      if (!std::isfinite(in.get<double>())) in.corrupt(at, "a transform that is not finite");
    }
  };
  const std::size_t at = in.pos();
  const std::string type = in.string();
  if (type == openvdb::math::NonlinearFrustumMap::mapType()) {
    doubles(6 + 2, at);  // its box, taper and depth, then its linear part, written as an AffineMap
    const std::size_t second = in.pos();
    if (in.string() != openvdb::math::AffineMap::mapType()) {
      in.corrupt(second, "a frustum transform whose linear part is not an AffineMap");
    }
    doubles(16, at);
    return;
  }
  const auto it = kLinearMapDoubles.find(type);
  if (it == kLinearMapDoubles.end()) in.corrupt(at, "a transform of unknown type \"" + type + "\"");
  doubles(it->second, at);
}

/// The grids tickfx reads: OpenVDB's numeric and vector trees, and PointDataGrid.
struct GridKind {
  ValueLayout value;
  bool points;
};

const std::map<std::string, GridKind>& gridKinds() {
  static const std::map<std::string, GridKind> kinds = {
      {openvdb::FloatGrid::gridType(), {{4, 2}, false}},
      {openvdb::DoubleGrid::gridType(), {{8, 2}, false}},
      {openvdb::Int32Grid::gridType(), {{4, 0}, false}},
      {openvdb::Int64Grid::gridType(), {{8, 0}, false}},
      {openvdb::Vec3IGrid::gridType(), {{12, 0}, false}},
      {openvdb::Vec3SGrid::gridType(), {{12, 6}, false}},
      {openvdb::Vec3DGrid::gridType(), {{24, 6}, false}},
      {openvdb::points::PointDataGrid::gridType(), {{4, 0}, true}},
  };
  return kinds;
}

/// One GridDescriptor (GridDescriptor::read): names, type, and where the grid lies.
struct Descriptor {
  std::string uniqueName;
  std::string type;  // as in the file, "_HalfFloat" included
  std::string parent;
  std::int64_t gridPos = 0, blockPos = 0, endPos = 0;
  std::string gridName() const { return openvdb::io::GridDescriptor::stripSuffix(uniqueName); }
};

/// Checks the grid described by `d`, beginning at `begin` and ending by `end`, as
/// io::Archive::readGrid reads it: its compression flags, metadata and transform, its tree's
/// topology, then its buffers, a regular tree's or a PointDataGrid's. Returns where its buffers
/// begin and where it ends.
std::pair<std::size_t, std::size_t> checkGrid(const std::string& file, std::uint32_t format,
                                              const Descriptor& d, std::size_t begin,
                                              std::size_t end) {
  std::string type = d.type;
  const std::string half = "_HalfFloat";  // GridDescriptor::HALF_FLOAT_TYPENAME_SUFFIX
  if (type.size() >= half.size() && type.compare(type.size() - half.size(), half.size(), half) == 0)
    type.erase(type.size() - half.size());
  const auto kind = gridKinds().find(type);
  if (kind == gridKinds().end()) {
    unreadable("a grid of type " + type + ", which tickfx does not read (it reads vector, number " +
               "and point data grids)");
  }
  if (!d.parent.empty()) {
    unreadable("an instance of grid '" + openvdb::io::GridDescriptor::nameAsString(d.parent) +
               "' (sharing its tree), which tickfx does not read");
  }
  if (kind->second.points && format < kPointsFormat) {
    unreadable("point data in OpenVDB file format " + std::to_string(format) + " (expected " +
               std::to_string(kPointsFormat) + ")");
  }
  Cursor in(file, begin, end, /*inGrid=*/true);
  const std::size_t at = in.pos();
  const auto compression = in.get<std::uint32_t>();  // Archive::readGridCompression
  if (compression & ~(kZip | kActiveMask | kBlosc)) {
    in.corrupt(at, "unknown compression flags " + std::to_string(compression));
  }
  const ValueLayout value = kind->second.value;
  const bool halfFloat =
      checkMetadata(in, (end - begin) / kLeafMaskBytes).halfFloat && value.halfSize != 0;
  checkTransform(in);
  const TreeStorage storage{value, compression, halfFloat, kind->second.points};
  const std::vector<LeafMask> leaves = checkTreeTopology(in, storage);
  const std::size_t block = in.pos();
  if (kind->second.points) {
    checkPointBuffers(in, leaves);
  } else {
    checkTreeBuffers(in, storage, leaves);
  }
  return {block, in.pos()};
}

}  // namespace
}  // namespace tickfx::vdbcheck

namespace tickfx {

std::string extractCheckedVdbGrid(const std::string& file, const std::string& name) {
  using vdbcheck::checkGrid, vdbcheck::checkMetadata, vdbcheck::Cursor, vdbcheck::Descriptor;
  using vdbcheck::kLeafMaskBytes, vdbcheck::kNewestFormat, vdbcheck::kOldestFormat;
  using vdbcheck::unreadable;
  using Kind = VdbFileError::Kind;
  Cursor in(file, 0, file.size(), /*inGrid=*/false);
  // ---- header (io::Archive::readHeader) ----
  if (file.size() < 8 || in.get<std::int64_t>() != openvdb::OPENVDB_MAGIC) {
    throw VdbFileError(Kind::NotVdb, "not an OpenVDB file");
  }
  const auto format = in.get<std::uint32_t>();
  if (format < kOldestFormat || format > kNewestFormat) {
    unreadable("OpenVDB file format " + std::to_string(format) + " (expected " +
               std::to_string(kOldestFormat) + " to " + std::to_string(kNewestFormat) +
               ", OpenVDB 3.0 to 10)");
  }
  const auto libraryMajor = in.get<std::uint32_t>();
  const auto libraryMinor = in.get<std::uint32_t>();
  const bool hasOffsets = in.get<char>() != 0;
  // The UUID, as text that boost::uuids reads whole (it would skip white space).
  const std::size_t uuidAt = in.pos();
  const char* uuid = in.take(36);
  for (std::size_t i = 0; i < 36; ++i) {
    const bool dash = i == 8 || i == 13 || i == 18 || i == 23;
    if (dash ? uuid[i] != '-' : !std::isxdigit(static_cast<unsigned char>(uuid[i]))) {
      in.corrupt(uuidAt, "a file UUID that is not one");
    }
  }
  checkMetadata(in, file.size() / kLeafMaskBytes);

  // ---- grid descriptors (io::File::readGridDescriptors), and with them the grid we want ----
  const std::size_t countAt = in.pos();
  const auto count = in.get<std::int32_t>();
  if (count < 0) in.corrupt(countAt, std::to_string(count) + " grids");
  std::vector<Descriptor> grids;
  for (std::int32_t i = 0; i < count; ++i) {
    const std::size_t at = in.pos();
    Descriptor d;
    d.uniqueName = in.string();
    d.type = in.string();
    d.parent = in.string();
    d.gridPos = in.get<std::int64_t>();
    d.blockPos = in.get<std::int64_t>();
    d.endPos = in.get<std::int64_t>();
    if (!hasOffsets) {
      // A stream (io::Stream writes no offsets): the grid follows, and only reading it tells where
      // it ends. The grids before the one we want must be of kinds this can read.
      const auto [block, end] = checkGrid(file, format, d, in.pos(), file.size());
      d.gridPos = static_cast<std::int64_t>(in.pos());
      d.blockPos = static_cast<std::int64_t>(block);
      d.endPos = static_cast<std::int64_t>(end);
      grids.push_back(d);
      if (d.gridName() == name) break;
      in.take(end - in.pos());
      continue;
    }
    const auto size = static_cast<std::int64_t>(file.size());
    if (d.endPos > size) {
      unreadable("the file is truncated: a grid ends at byte " + std::to_string(d.endPos) + " of " +
                 std::to_string(size));
    }
    if (d.gridPos != static_cast<std::int64_t>(in.pos()) || d.blockPos < d.gridPos ||
        d.endPos < d.blockPos) {
      in.corrupt(at, "grid offsets " + std::to_string(d.gridPos) + ", " +
                         std::to_string(d.blockPos) + ", " + std::to_string(d.endPos) +
                         " (expected increasing, from the end of the descriptor)");
    }
    grids.push_back(d);
    in.take(static_cast<std::uint64_t>(d.endPos - d.gridPos));
  }

  // io::File::findDescriptor: the first grid of that name, or "name[N]" for the N-th of a name.
  const Descriptor* wanted = nullptr;
  for (const Descriptor& d : grids) {
    if (d.gridName() == name) {
      wanted = &d;
      break;
    }
  }
  if (wanted == nullptr) {
    const std::string unique = openvdb::io::GridDescriptor::stringAsUniqueName(name);
    for (const Descriptor& d : grids) {
      if (unique != name && (d.uniqueName == unique || d.uniqueName == name)) {
        wanted = &d;
        break;
      }
    }
  }
  if (wanted == nullptr) {
    // The names as io::File lists them: sorted, as given by name.
    std::vector<std::string> names;
    for (const Descriptor& d : grids) names.push_back(d.gridName());
    std::vector<std::size_t> order(grids.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(),
                     [&](std::size_t a, std::size_t b) { return names[a] < names[b]; });
    std::string list;
    for (const std::size_t i : order) {
      list += (list.empty() ? "" : ", ") +
              openvdb::io::GridDescriptor::nameAsString(grids[i].uniqueName);
    }
    throw VdbFileError(Kind::NoSuchGrid, list.empty()
                                             ? "the file holds no grids: empty or truncated"
                                             : "the file has: " + list);
  }
  const auto gridPos = static_cast<std::size_t>(wanted->gridPos);
  const auto endPos = static_cast<std::size_t>(wanted->endPos);
  if (hasOffsets) {
    const auto [block, end] = checkGrid(file, format, *wanted, gridPos, endPos);
    if (block != static_cast<std::size_t>(wanted->blockPos) || end != endPos) {
      unreadable("the file is corrupt: the grid's topology ends at byte " + std::to_string(block) +
                 " and its data at byte " + std::to_string(end) + " where its descriptor says " +
                 std::to_string(wanted->blockPos) + " and " + std::to_string(endPos));
    }
  }

  // ---- the stream OpenVDB reads: a header, no metadata, the one descriptor, the grid ----
  std::string stream;
  auto put = [&](const auto& v) { stream.append(reinterpret_cast<const char*>(&v), sizeof v); };
  auto putString = [&](const std::string& s) {
    put(static_cast<std::uint32_t>(s.size()));
    stream += s;
  };
  put(static_cast<std::int64_t>(openvdb::OPENVDB_MAGIC));
  put(format);
  put(libraryMajor);
  put(libraryMinor);
  put(char{0});  // no grid offsets: a stream
  stream.append(uuid, 36);
  put(std::uint32_t{0});  // file metadata: none (tickfx reads none)
  put(std::int32_t{1});   // one grid
  putString(wanted->uniqueName);
  putString(wanted->type);
  putString(wanted->parent);
  for (int i = 0; i < 3; ++i) put(std::int64_t{0});
  stream.append(file, gridPos, endPos - gridPos);
  return stream;
}

}  // namespace tickfx
