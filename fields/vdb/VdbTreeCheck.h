// Checking a grid's tree the way OpenVDB 10 reads it: the topology (RootNode, InternalNode 5 and 4,
// LeafNode 3 readTopology), the leaves' values (LeafNode::readBuffers), node values as
// io::readCompressedValues stores them, and the blosc blocks every part of a grid may hold.
// Internal to tickfx_vdb (VdbArchiveCheck.cpp and VdbPointsCheck.cpp use it).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "fields/vdb/VdbCheckReader.h"

namespace tickfx::vdbcheck {

// Compression flags of a grid (io::COMPRESS_*).
constexpr std::uint32_t kZip = 0x1, kActiveMask = 0x2, kBlosc = 0x4;
// A leaf's value mask: 512 voxels, a bit each.
constexpr std::size_t kLeafMaskBytes = 64;
using LeafMask = std::array<char, kLeafMaskBytes>;

/// What a grid's values are: their size in bytes, and the size of the half floats OpenVDB stores
/// real values as in a grid saved as half (io::RealToHalf).
struct ValueLayout {
  std::size_t size;
  std::size_t halfSize;
};

/// How a tree's values are stored, from what io::Archive reads before the tree.
struct TreeStorage {
  ValueLayout value;
  std::uint32_t compression;  // kZip, kActiveMask and kBlosc: the grid's compression flags
  bool half;                  // the values are stored as half floats
  bool points;                // a PointDataGrid's tree (its background must be zero)
};

/// Tree::readTopology: the root's tiles and children, in order, unique and aligned to their nodes,
/// then each internal node's masks and values and each leaf's value mask. Returns the leaves'
/// value masks in the order their buffers follow.
std::vector<LeafMask> checkTreeTopology(Cursor& in, const TreeStorage& storage);

/// Tree::readBuffers of a tree that is not a PointDataGrid's: each leaf's value mask, the same as
/// in `leaves` (the topology's), then its 512 values.
void checkTreeBuffers(Cursor& in, const TreeStorage& storage, const std::vector<LeafMask>& leaves);

/// LeafNode::readBuffers reads the value mask again from a stream; OpenVDB writes it twice the
/// same, and the values are counted by the one in the topology, so the two must be equal.
void checkLeafMask(Cursor& in, const LeafMask& topology);

/// A blosc block OpenVDB decompresses with blosc_decompress_ctx, which takes the block's length
/// from its own header: safe only when blosc validates that header against the block's real length
/// (`bytes`). Then the block must decompress to `expected` bytes, or (`padded`) to the 128 bytes
/// OpenVDB pads smaller point arrays to. `at` is where the block starts, for the message.
///
/// The block is decompressed here once, as OpenVDB will: a header can be sound over a damaged body,
/// and OpenVDB throwing from the middle of a paged attribute read leaks the page handles its
/// AttributeArray keeps in a union (no destructor runs for them).
void checkBlosc(const Cursor& in, std::size_t at, const char* block, std::uint64_t bytes,
                std::uint64_t expected, bool padded);

}  // namespace tickfx::vdbcheck
