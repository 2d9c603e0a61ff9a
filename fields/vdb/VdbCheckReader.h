// What the checks of an untrusted .vdb file share: the reader of its bytes, and the metadata maps
// every level of the file holds (the file's, a grid's, a point attribute set's defaults). The
// checks are split as OpenVDB 10 splits its readers: VdbArchiveCheck.cpp (io::Archive, io::File,
// MetaMap, math::Transform), VdbTreeCheck.cpp (the tree's nodes and compressed values),
// VdbPointsCheck.cpp (points::PointDataLeafNode and its attribute arrays). Internal to tickfx_vdb;
// it includes none of OpenVDB's headers.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>

#include "fields/vdb/VdbFileCheck.h"

namespace tickfx::vdbcheck {

[[noreturn]] inline void unreadable(const std::string& what) {
  throw VdbFileError(VdbFileError::Kind::Unreadable, what);
}

/// Reads little-endian values (x86-64, as OpenVDB writes them) from [pos, end) of the file. A read
/// past `end` is "the file is truncated" in the file's header and descriptors, and corruption in a
/// grid (its descriptor says where it ends, so a size read inside it that runs further is wrong).
class Cursor {
 public:
  Cursor(const std::string& file, std::size_t pos, std::size_t end, bool inGrid)
      : file_(file), pos_(pos), end_(end), inGrid_(inGrid) {}

  std::size_t pos() const { return pos_; }
  std::uint64_t left() const { return end_ - pos_; }

  [[noreturn]] void corrupt(std::size_t at, const std::string& what) const {
    unreadable("the file is corrupt at byte " + std::to_string(at) + ": " + what);
  }
  const char* take(std::uint64_t n) {
    if (n > left()) {
      if (!inGrid_) unreadable("the file is truncated");
      corrupt(pos_, "a size that runs past the grid's end at byte " + std::to_string(end_));
    }
    const char* p = file_.data() + pos_;
    pos_ += static_cast<std::size_t>(n);
    return p;
  }
  template <class T>
  T get() {
    T v;
    std::memcpy(&v, take(sizeof v), sizeof v);
    return v;
  }
  /// io::readString: a uint32 length and the bytes.
  std::string string() {
    const auto n = get<std::uint32_t>();
    return std::string(take(n), n);
  }

 private:
  const std::string& file_;
  std::size_t pos_;
  std::size_t end_;
  bool inGrid_;
};

/// What a grid's metadata says about how its values are stored.
struct MetadataFound {
  bool halfFloat = false;  // is_saved_as_half_float: real values are stored as half floats
};

/// MetaMap::readMeta: a count, then per entry a name, a type name, a byte count and the value.
/// Registered types are read as OpenVDB reads them (a fixed size whatever the count says, so the
/// count must be that size; strings and io::DelayedLoadMetadata by their own layout); unknown types
/// as raw bytes. `leafBound` bounds the leaf count a DelayedLoadMetadata may claim. Defined in
/// VdbArchiveCheck.cpp.
MetadataFound checkMetadata(Cursor& in, std::uint64_t leafBound);

}  // namespace tickfx::vdbcheck
