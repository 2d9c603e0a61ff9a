#include "fields/vdb/VdbPointsCheck.h"

#include <openvdb/points/AttributeArray.h>
#include <openvdb/points/AttributeSet.h>

#include <cstddef>
#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

namespace tickfx::vdbcheck {
namespace {

// A PointDataGrid leaf's voxel values: 512 uint32 offsets.
constexpr std::uint64_t kLeafOffsetBytes = 512 * 4;

/// The buffers of one PointDataGrid's leaves (points::PointDataLeafNode::readBuffers).
class PointBufferCheck {
 public:
  PointBufferCheck(Cursor& in, const std::vector<LeafMask>& leaves) : in_(in), leaves_(leaves) {}

  void check() {
    // Grid::readBuffers: a pass count, then every leaf once per pass.
    const std::size_t at = in_.pos();
    const auto passes = in_.get<std::uint16_t>();
    // OpenVDB writes 2n + 4 passes for leaves of at most n attributes, and none for no leaves.
    if (passes == 0 ? !leaves_.empty() : passes < 4 || passes % 2 != 0) {
      in_.corrupt(at, std::to_string(passes) + " passes over " + std::to_string(leaves_.size()) +
                          " leaves");
    }
    const std::uint32_t attributes = passes == 0 ? 0 : (passes - 4u) / 2u;
    std::vector<PointLeaf> leaves(leaves_.size());
    std::map<std::uint32_t, PagedStream> streams;
    for (std::uint32_t pass = 0; pass < passes; ++pass) {
      bool matching = false;  // the shared descriptor (the "hasMatchingDescriptor" aux data)
      std::shared_ptr<const std::vector<std::size_t>> shared;
      for (std::size_t l = 0; l < leaves.size(); ++l) {
        PointLeaf& leaf = leaves[l];
        const auto count = static_cast<std::uint32_t>(leaf.arrays.size());
        if (pass == 0) {
          in_.get<std::uint16_t>();  // the voxel buffer's size, for seeking
        } else if (pass == 1) {
          const std::size_t descriptorAt = in_.pos();
          if (matching) {
            leaf.storage = shared;
          } else {
            const auto header = in_.get<std::uint8_t>();
            if (header > 3) in_.corrupt(descriptorAt, "unknown point leaf header flags");
            leaf.storage = descriptor();
            if (header & 1) {
              matching = true;
              shared = leaf.storage;
            }
            if (header & 2) in_.take(in_.get<std::uint64_t>());  // bytes for future use
          }
          if (leaf.storage->size() > attributes) {
            in_.corrupt(descriptorAt, "a leaf of " + std::to_string(leaf.storage->size()) +
                                          " attributes in " + std::to_string(passes) + " passes");
          }
          for (const std::size_t storage : *leaf.storage) leaf.arrays.push_back(array(storage));
        } else if (pass < attributes + 2) {
          if (pass - 2 < count) sizes(streams[pass - 2], leaf.arrays[pass - 2]);
        } else if (pass == attributes + 2) {
          voxels(leaves_[l]);
        } else if (pass < 2 * attributes + 3) {
          const std::uint32_t a = pass - attributes - 3;
          if (a < count) contents(streams[a], leaf.arrays[a]);
          if (pass > attributes + 3) streams.erase(a - 1);
        } else if (pass < 2 * count + 4) {
          streams.erase(pass - attributes - 4);
        }
      }
    }
  }

 private:
  /// An attribute array as TypedAttributeArray::readMetadata leaves it.
  struct Array {
    bool uniform = false;
    bool paged = false;
    std::uint64_t stored = 0;    // its bytes in the file (compressed or not)
    std::uint64_t expected = 0;  // the bytes of its data: (uniform ? 1 : dataSize()) * storage size
    std::size_t page = 0;        // paged: its page in its attribute's stream
  };
  struct Page {
    std::int32_t compressed;  // > 0: a blosc block of that many bytes; < 0: raw, -that many
    std::int32_t uncompressed;
    bool loaded = false;
  };
  /// compression::PagedInputStream: the pages of one attribute index across the leaves.
  struct PagedStream {
    std::int64_t byteIndex = 0;
    std::int64_t uncompressed = 0;
    std::vector<Page> pages;
  };
  struct PointLeaf {
    std::shared_ptr<const std::vector<std::size_t>> storage;  // per attribute, from the descriptor
    std::vector<Array> arrays;
  };

  /// AttributeSet::Descriptor::read: types (name and codec), the names and positions of the
  /// attributes, groups, and default-value metadata. Returns each attribute's storage size.
  std::shared_ptr<const std::vector<std::size_t>> descriptor() {
    std::size_t at = in_.pos();
    const auto count = in_.get<std::uint64_t>();
    if (count > in_.left() / 8) in_.corrupt(at, std::to_string(count) + " attributes");
    auto storage = std::make_shared<std::vector<std::size_t>>();
    for (std::uint64_t i = 0; i < count; ++i) {
      at = in_.pos();
      openvdb::NamePair type;
      type.first = in_.string();
      type.second = in_.string();
      storage->push_back(storageSize(at, type));
    }
    std::vector<bool> seen(count, false);
    std::set<std::string> names;
    for (std::uint64_t i = 0; i < count; ++i) {
      at = in_.pos();
      const std::string name = in_.string();
      const auto pos = in_.get<std::uint64_t>();
      if (!openvdb::points::AttributeSet::Descriptor::validName(name) ||
          !names.insert(name).second || pos >= count || seen[pos]) {
        in_.corrupt(at, "attribute \"" + name + "\" at position " + std::to_string(pos) + " of " +
                            std::to_string(count) +
                            " (expected unique valid names, one a position)");
      }
      seen[pos] = true;
    }
    at = in_.pos();
    const auto groups = in_.get<std::uint64_t>();
    if (groups > in_.left() / 12) in_.corrupt(at, std::to_string(groups) + " groups");
    names.clear();
    for (std::uint64_t i = 0; i < groups; ++i) {
      at = in_.pos();
      const std::string name = in_.string();
      in_.get<std::uint64_t>();  // its bit among the group attributes' bits
      if (!openvdb::points::AttributeSet::Descriptor::validName(name) ||
          !names.insert(name).second) {
        in_.corrupt(at, "group \"" + name + "\" (expected unique valid names)");
      }
    }
    checkMetadata(in_, 0);
    return storage;
  }

  std::size_t storageSize(std::size_t at, const openvdb::NamePair& type) {
    const auto known = storageSizes_.find(type);
    if (known != storageSizes_.end()) return known->second;
    if (!openvdb::points::AttributeArray::isRegistered(type)) {
      in_.corrupt(at, "an attribute of unknown type \"" + type.first + "\" (codec \"" +
                          type.second + "\")");
    }
    const std::size_t size = openvdb::points::AttributeArray::create(type, 1, 1)->storageTypeSize();
    storageSizes_.emplace(type, size);
    return size;
  }

  /// TypedAttributeArray::readMetadata.
  Array array(std::size_t storage) {
    const std::size_t at = in_.pos();
    const auto bytes = in_.get<std::uint64_t>();
    const auto flags = in_.get<std::uint8_t>();
    const auto serialization = in_.get<std::uint8_t>();
    const auto size = in_.get<std::uint32_t>();
    const std::uint32_t stride =
        serialization & 0x1 ? in_.get<std::uint32_t>() : 1;  // WRITESTRIDED
    // Flags OpenVDB writes: transient, hidden, (old) out of core, constant stride, streaming.
    if (bytes < 6 || flags >= 0x20 || serialization >= 0x10) {
      in_.corrupt(at, "attribute array metadata OpenVDB cannot have written");
    }
    Array a;
    a.uniform = serialization & 0x2;  // WRITEUNIFORM
    a.paged = serialization & 0x8;    // WRITEPAGED
    a.stored = bytes - 6;             // less the flags and the size
    // dataSize(), which OpenVDB computes in 32 bits: size · stride, or the total size.
    const std::uint64_t values = flags & 0x8 ? std::uint64_t{size} * stride : stride;
    if (values > std::numeric_limits<std::uint32_t>::max()) {
      in_.corrupt(at, "an attribute array of " + std::to_string(values) + " values");
    }
    a.expected = (a.uniform ? 1 : values) * storage;
    // A paged array takes exactly its data's bytes from its page; a uniform one is stored raw.
    if ((a.paged || a.uniform) && a.stored != a.expected) {
      in_.corrupt(at, "an attribute array of " + std::to_string(a.stored) + " bytes where " +
                          std::to_string(a.expected) + " are expected");
    }
    // PageHandle::read asserts a size of at least 1 and fits it in an int.
    if (a.paged && (a.expected == 0 || a.expected > std::numeric_limits<std::int32_t>::max())) {
      in_.corrupt(at, "a paged attribute array of " + std::to_string(a.expected) + " bytes");
    }
    return a;
  }

  /// The size pass of a paged array (PagedInputStream::createHandle): a new page header when the
  /// stream's page is used up, then a handle on the array's bytes in that page.
  void sizes(PagedStream& s, Array& a) {
    if (!a.paged) return;
    if (s.byteIndex == s.uncompressed) {
      const std::size_t at = in_.pos();
      Page page;
      page.compressed = in_.get<std::int32_t>();
      page.uncompressed = page.compressed > 0 ? in_.get<std::int32_t>() : -page.compressed;
      // Page::readHeader asserts both are non-zero.
      if (page.compressed == 0 || page.compressed == std::numeric_limits<std::int32_t>::min() ||
          page.uncompressed <= 0) {
        in_.corrupt(at, "an attribute page header of " + std::to_string(page.compressed) + " and " +
                            std::to_string(page.uncompressed) + " bytes");
      }
      s.pages.push_back(page);
      s.uncompressed = page.uncompressed;
      s.byteIndex = 0;
    }
    // The handle must lie in the page (createHandle asserts this before the next handle).
    if (static_cast<std::int64_t>(a.expected) > s.uncompressed - s.byteIndex) {
      in_.corrupt(in_.pos(), "an attribute array of " + std::to_string(a.expected) +
                                 " bytes past the end of its page of " +
                                 std::to_string(s.uncompressed) + " bytes");
    }
    a.page = s.pages.size() - 1;
    s.byteIndex += static_cast<std::int64_t>(a.expected);
  }

  /// The buffer pass of an array: PagedInputStream::read then PageHandle::read for a paged one,
  /// TypedAttributeArray::readBuffers for another.
  void contents(PagedStream& s, const Array& a) {
    const std::size_t at = in_.pos();
    if (!a.paged) {
      std::uint8_t blosc = 0;
      if (!a.uniform) blosc = in_.get<std::uint8_t>();
      if (blosc > 1) in_.corrupt(at, "an attribute array compressed in an unknown way");
      const char* block = in_.take(a.stored);
      if (blosc == 1) {
        checkBlosc(in_, at + 1, block, a.stored, a.expected, /*padded=*/true);
      } else if (a.stored != a.expected) {
        in_.corrupt(at, "an attribute array of " + std::to_string(a.stored) + " bytes where " +
                            std::to_string(a.expected) + " are expected");
      }
      return;
    }
    if (s.pages.empty() || s.byteIndex > s.uncompressed) {
      in_.corrupt(at, "attribute pages that do not match their headers");
    }
    if (s.byteIndex == s.uncompressed) {
      // The stream reads the page of this array's handle: it must be the next one not yet read
      // (reading a page twice asserts).
      Page& page = s.pages[a.page];
      if (page.loaded) in_.corrupt(at, "attribute pages that do not match their headers");
      s.uncompressed = page.uncompressed;
      if (page.compressed > 0) {
        const auto bytes = static_cast<std::uint64_t>(page.compressed);
        const char* block = in_.take(bytes);
        checkBlosc(in_, at, block, bytes, static_cast<std::uint64_t>(page.uncompressed),
                   /*padded=*/true);
      } else {
        in_.take(static_cast<std::uint64_t>(page.uncompressed));
      }
      page.loaded = true;
      s.byteIndex = 0;
    }
    s.byteIndex += static_cast<std::int64_t>(a.expected);
    // PageHandle::read copies from the page's buffer: a page never read has none.
    if (!s.pages[a.page].loaded) in_.corrupt(at, "attribute pages that do not match their headers");
  }

  /// The voxel pass: the value mask again, then the offsets (the readCompressedValues of
  /// PointDataIndex32: a 16-bit size, 0xFFFF for raw, else a blosc block).
  void voxels(const LeafMask& mask) {
    checkLeafMask(in_, mask);
    const std::size_t at = in_.pos();
    const auto bytes = in_.get<std::uint16_t>();
    if (bytes == std::numeric_limits<std::uint16_t>::max()) {
      in_.take(kLeafOffsetBytes);
      return;
    }
    const char* block = in_.take(bytes);
    checkBlosc(in_, at + 2, block, bytes, kLeafOffsetBytes, /*padded=*/false);
  }

  Cursor& in_;
  const std::vector<LeafMask>& leaves_;  // the leaves' value masks, in reading order
  std::map<openvdb::NamePair, std::size_t> storageSizes_;
};

}  // namespace

void checkPointBuffers(Cursor& in, const std::vector<LeafMask>& leaves) {
  PointBufferCheck(in, leaves).check();
}

}  // namespace tickfx::vdbcheck
