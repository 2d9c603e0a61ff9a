#include "fields/vdb/VdbTreeCheck.h"

#include <blosc.h>
#include <openvdb/math/Coord.h>
#include <openvdb/points/StreamCompression.h>

#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace tickfx::vdbcheck {
namespace {

std::uint64_t bitsOn(const char* mask, std::size_t bytes) {
  std::uint64_t n = 0;
  for (std::size_t i = 0; i < bytes; ++i) n += std::popcount(static_cast<unsigned char>(mask[i]));
  return n;
}

bool bitOn(const char* mask, std::size_t i) {
  return (static_cast<unsigned char>(mask[i / 8]) >> (i % 8)) & 1u;
}

/// One tree's nodes: RootNode, InternalNode 5 and 4, LeafNode 3.
class NodeCheck {
 public:
  NodeCheck(Cursor& in, const TreeStorage& storage) : in_(in), storage_(storage) {}

  std::vector<LeafMask> topology() {
    root();
    return std::move(leafMasks_);
  }

  void leafBuffers(const std::vector<LeafMask>& leaves) {
    for (const LeafMask& mask : leaves) {
      checkLeafMask(in_, mask);
      values(512, mask.data(), kLeafMaskBytes);
    }
  }

 private:
  // ---- topology ------------------------------------------------------------------------------

  void root() {
    const std::size_t at = in_.pos();
    if (in_.get<std::int32_t>() != 1) in_.corrupt(at, "a tree with other than one buffer");
    const std::size_t backgroundAt = in_.pos();
    const char* background = in_.take(storage_.value.size);
    // A PointDataGrid's leaves are made with the background as their value, and OpenVDB asserts
    // that it is zero (PointDataLeafNode::assertNonModifiableUnlessZero).
    if (storage_.points &&
        std::any_of(background, background + storage_.value.size, [](char c) { return c != 0; })) {
      in_.corrupt(backgroundAt, "a point data tree whose background is not zero");
    }
    const auto tiles = in_.get<std::uint32_t>();
    const auto children = in_.get<std::uint32_t>();
    // The root's table is a std::map: OpenVDB writes tiles, then children, each in the map's
    // order, and reads buffers in that order. Keys in order, unique and node-aligned keep the
    // file's order the reading order and every lookup finding its node.
    std::vector<openvdb::Coord> tileKeys;
    for (std::uint32_t i = 0; i < tiles; ++i) {
      const openvdb::Coord key = rootKey(tileKeys);
      in_.take(storage_.value.size);
      const std::size_t active = in_.pos();
      if (in_.get<std::uint8_t>() > 1) in_.corrupt(active, "a tile that is neither on nor off");
      tileKeys.push_back(key);
    }
    std::vector<openvdb::Coord> childKeys;
    for (std::uint32_t i = 0; i < children; ++i) {
      const std::size_t keyAt = in_.pos();
      const openvdb::Coord key = rootKey(childKeys);
      if (std::binary_search(tileKeys.begin(), tileKeys.end(), key)) {
        in_.corrupt(keyAt, "a child of the root where it has a tile");
      }
      childKeys.push_back(key);
      internal(5);
    }
  }

  openvdb::Coord rootKey(const std::vector<openvdb::Coord>& before) {
    const std::size_t at = in_.pos();
    openvdb::Coord key;
    for (int c = 0; c < 3; ++c) key[c] = in_.get<std::int32_t>();
    constexpr std::int32_t kAlign = (1 << 12) - 1;  // a root child spans 2^(5+4+3) voxels
    if ((key[0] & kAlign) || (key[1] & kAlign) || (key[2] & kAlign) ||
        (!before.empty() && !(before.back() < key))) {
      in_.corrupt(at, "a root node entry out of order or not aligned to its node");
    }
    return key;
  }

  void internal(int log2) {
    const std::size_t bytes = (std::size_t{1} << (3 * log2)) / 8;
    const std::size_t at = in_.pos();
    const char* childMask = in_.take(bytes);
    const char* valueMask = in_.take(bytes);
    for (std::size_t i = 0; i < bytes; ++i) {
      if (childMask[i] & valueMask[i]) in_.corrupt(at, "a node value that is both child and tile");
    }
    values(std::uint64_t{1} << (3 * log2), valueMask, bytes);
    for (std::size_t i = 0; i < bytes * 8; ++i) {
      if (!bitOn(childMask, i)) continue;
      if (log2 == 5) {
        internal(4);
      } else {
        LeafMask mask;
        std::memcpy(mask.data(), in_.take(kLeafMaskBytes), kLeafMaskBytes);
        leafMasks_.push_back(mask);
      }
    }
  }

  // ---- values (io::readCompressedValues, io::readData) ------------------------------------------

  void values(std::uint64_t count, const char* valueMask, std::size_t maskBytes) {
    const std::size_t valueSize = storage_.value.size;
    const std::size_t at = in_.pos();
    const auto layout = in_.get<std::int8_t>();
    if (layout < 0 || layout > 6) in_.corrupt(at, "unknown node value compression");
    if (layout == 2 || layout == 4 || layout == 5) in_.take(valueSize);  // an inactive value
    if (layout == 5) in_.take(valueSize);                                // a second one
    if (layout >= 3 && layout <= 5) in_.take(maskBytes);                 // which is which
    // With mask compression, only the active values are stored.
    const std::uint64_t stored =
        (storage_.compression & kActiveMask) && layout != 6 ? bitsOn(valueMask, maskBytes) : count;
    if (storage_.half && stored == 0) return;  // io::HalfReader reads nothing then
    data(stored * (storage_.half ? storage_.value.halfSize : valueSize));
  }

  void data(std::uint64_t bytes) {
    if (!(storage_.compression & (kBlosc | kZip))) {
      in_.take(bytes);
      return;
    }
    const std::size_t at = in_.pos();
    const auto n = in_.get<std::int64_t>();
    if (n <= 0) {
      // Stored raw: OpenVDB reads -n bytes into its buffer of `bytes` before comparing the two.
      if (n == std::numeric_limits<std::int64_t>::min() ||
          static_cast<std::uint64_t>(-n) != bytes) {
        in_.corrupt(at, "a block of " + std::to_string(n) + " bytes where " +
                            std::to_string(bytes) + " are expected");
      }
      in_.take(bytes);
      return;
    }
    const char* block = in_.take(static_cast<std::uint64_t>(n));
    // zlib is given the block's length and the buffer's size, and OpenVDB compares what it gets:
    // a zip block needs no more. Blosc trusts the block's header.
    if (storage_.compression & kBlosc) {
      checkBlosc(in_, at + 8, block, static_cast<std::uint64_t>(n), bytes, /*padded=*/false);
    }
  }

  Cursor& in_;
  TreeStorage storage_;
  std::vector<LeafMask> leafMasks_;  // in reading order
};

}  // namespace

std::vector<LeafMask> checkTreeTopology(Cursor& in, const TreeStorage& storage) {
  return NodeCheck(in, storage).topology();
}

void checkTreeBuffers(Cursor& in, const TreeStorage& storage, const std::vector<LeafMask>& leaves) {
  NodeCheck(in, storage).leafBuffers(leaves);
}

void checkLeafMask(Cursor& in, const LeafMask& topology) {
  const std::size_t at = in.pos();
  if (std::memcmp(in.take(kLeafMaskBytes), topology.data(), kLeafMaskBytes) != 0) {
    in.corrupt(at, "a leaf's value mask unlike the one in the tree's topology");
  }
}

void checkBlosc(const Cursor& in, std::size_t at, const char* block, std::uint64_t bytes,
                std::uint64_t expected, bool padded) {
  std::size_t nbytes = 0;
  if (bytes < BLOSC_MIN_HEADER_LENGTH || blosc_cbuffer_validate(block, bytes, &nbytes) != 0) {
    in.corrupt(at, "a blosc block of " + std::to_string(bytes) + " bytes that blosc refuses");
  }
  const auto pad = static_cast<std::uint64_t>(openvdb::compression::BLOSC_PAD_BYTES);
  if (nbytes != expected && !(padded && expected <= pad && nbytes == pad)) {
    in.corrupt(at, "a blosc block holding " + std::to_string(nbytes) + " bytes where " +
                       std::to_string(expected) + " are expected");
  }
  // nbytes is now bounded by the structure the file declares, which the cursor has checked.
  std::vector<char> out(nbytes);
  const int got = blosc_decompress_ctx(block, out.data(), out.size(), /*numinternalthreads=*/1);
  if (got < 0 || static_cast<std::size_t>(got) != nbytes) {
    in.corrupt(at, "a blosc block of " + std::to_string(bytes) + " bytes that does not decompress");
  }
}

}  // namespace tickfx::vdbcheck
