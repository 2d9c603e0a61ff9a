#include "io/cache/VdbPointsEncoder.h"

#include <openvdb/io/Archive.h>
#include <openvdb/io/io.h>
#include <openvdb/openvdb.h>
#include <openvdb/points/PointDataGrid.h>
#include <openvdb/points/StreamCompression.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <ios>
#include <limits>
#include <memory>
#include <mutex>
#include <new>
#include <ostream>
#include <sstream>
#include <stdexcept>
#include <streambuf>
#include <string>
#include <thread>
#include <type_traits>
#include <utility>
#include <vector>

#include "io/util/ProfiledTbb.h"
#include "particles/Column.h"

namespace tickfx::io {

namespace {

constexpr std::size_t kHugePage = std::size_t{2} << 20;

// Large blocks, kept when freed for the next frame's buffers of about the same size: a frame's
// cache needs the same buffers as the last one, and faulting fresh pages in (and handing them
// back) cost more than the copying in a virtual machine. Blocks are taken by best fit within a
// quarter over the size asked, and made an eighth larger than asked so that a growing frame
// still fits; at most kKeptBytes of free blocks are kept, the least recently freed handed back
// first. The memory is the process's until it exits (reachable from here, not leaked).
class LargeBlocks {
 public:
  static LargeBlocks& instance() {
    static LargeBlocks* const blocks = new LargeBlocks;  // never destroyed: used until exit
    return *blocks;
  }

  void* take(std::size_t size) {
    {
      const std::lock_guard lock(mutex_);
      Block* best = nullptr;
      for (Block& b : blocks_) {
        if (!b.free || b.capacity < size || b.capacity - size > size / 4 + kHugePage) continue;
        if (best == nullptr || b.capacity < best->capacity) best = &b;
      }
      if (best != nullptr) {
        best->free = false;
        freeBytes_ -= best->capacity;
        return best->p;
      }
    }
    const std::size_t capacity = (size + size / 8 + kHugePage - 1) / kHugePage * kHugePage;
    void* p = allocateColumnStorage(capacity);  // on huge pages, as the pool's columns
    const std::lock_guard lock(mutex_);
    blocks_.push_back(Block{p, capacity, false, 0});
    return p;
  }

  // False when `p` is not a large block (the caller frees it).
  bool give(void* p) {
    const std::lock_guard lock(mutex_);
    const auto block =
        std::find_if(blocks_.begin(), blocks_.end(), [&](const Block& b) { return b.p == p; });
    if (block == blocks_.end()) return false;
    block->free = true;
    block->freedAt = ++clock_;
    freeBytes_ += block->capacity;
    while (freeBytes_ > kKeptBytes) {
      auto oldest = blocks_.end();
      for (auto b = blocks_.begin(); b != blocks_.end(); ++b) {
        if (b->free && (oldest == blocks_.end() || b->freedAt < oldest->freedAt)) oldest = b;
      }
      freeBytes_ -= oldest->capacity;
      std::free(oldest->p);
      blocks_.erase(oldest);
    }
    return true;
  }

 private:
  static constexpr std::size_t kKeptBytes = std::size_t{2} << 30;
  struct Block {
    void* p = nullptr;
    std::size_t capacity = 0;
    bool free = false;
    std::uint64_t freedAt = 0;
  };
  std::mutex mutex_;
  std::vector<Block> blocks_;
  std::size_t freeBytes_ = 0;
  std::uint64_t clock_ = 0;
};

}  // namespace

void FileBytes::Free::operator()(void* p) const {
  if (p != nullptr && !LargeBlocks::instance().give(p)) std::free(p);
}

FileBytes::Storage FileBytes::allocate(std::size_t size) {
  if (size >= kHugePage) return Storage(static_cast<char*>(LargeBlocks::instance().take(size)));
  void* p = std::malloc(std::max<std::size_t>(size, 1));
  if (p == nullptr) throw std::bad_alloc();
  return Storage(static_cast<char*>(p));
}

namespace {

namespace vdbp = openvdb::points;
using Leaf = vdbp::PointDataTree::LeafNodeType;

// ---- memory as a stream -----------------------------------------------------------------------

// An output stream buffer over memory that grows, with what Archive::write() asks of a stream:
// writes, tellp, seekp back to patch what it wrote (a grid's offsets), seekp to the end; and
// skip(), a stretch at the end whose bytes are made elsewhere (the gap: at most one, not held).
// Positions are the file's, the gap's bytes counted. Unbuffered: every write goes to xsputn()
// or overflow(), which copy it into place.
class MemorySink final : public std::streambuf {
 public:
  explicit MemorySink(std::size_t capacity) { grow(std::max<std::size_t>(capacity, 64)); }

  /// Moves the put position (which must be at the end) past `n` bytes that the sink leaves out,
  /// and returns where they start.
  std::size_t skip(std::size_t n) {
    if (pos_ != size_ || gapSize_ != 0) throw std::logic_error("MemorySink::skip twice or inside");
    gapAt_ = size_;
    gapSize_ = n;
    size_ += n;
    pos_ = size_;
    return gapAt_;
  }
  /// The bytes held: those before the gap, then those after it.
  const char* data() const { return data_.get(); }
  std::size_t held() const { return size_ - gapSize_; }
  /// The file's size, the gap's bytes counted.
  std::size_t size() const { return size_; }
  std::size_t gapAt() const { return gapAt_; }
  FileBytes release() && { return FileBytes(std::move(data_), held()); }

 protected:
  int_type overflow(int_type c) override {
    if (traits_type::eq_int_type(c, traits_type::eof())) return traits_type::not_eof(c);
    const char ch = traits_type::to_char_type(c);
    put(&ch, 1);
    return c;
  }
  std::streamsize xsputn(const char* s, std::streamsize n) override {
    put(s, static_cast<std::size_t>(n));
    return n;
  }
  pos_type seekoff(off_type off, std::ios_base::seekdir dir,
                   std::ios_base::openmode which) override {
    const auto base = static_cast<off_type>(dir == std::ios_base::beg   ? 0
                                            : dir == std::ios_base::cur ? pos_
                                                                        : size_);
    return seekpos(pos_type(base + off), which);
  }
  pos_type seekpos(pos_type at, std::ios_base::openmode which) override {
    const auto offset = static_cast<off_type>(at);
    if (!(which & std::ios_base::out) || offset < 0 || static_cast<std::size_t>(offset) > size_)
      return pos_type(off_type(-1));
    pos_ = static_cast<std::size_t>(offset);
    return at;
  }

 private:
  void put(const char* s, std::size_t n) {
    const std::size_t gapEnd = gapAt_ + gapSize_;
    if (gapSize_ != 0 && pos_ < gapEnd && pos_ + n > gapAt_)
      throw std::logic_error("MemorySink: a write into the gap");
    const std::size_t at = gapSize_ != 0 && pos_ >= gapEnd ? pos_ - gapSize_ : pos_;
    if (at + n > capacity_) grow(std::max(at + n, 2 * capacity_));
    std::memcpy(data_.get() + at, s, n);
    pos_ += n;
    size_ = std::max(size_, pos_);
  }
  // Capacity `capacity`, keeping what is written.
  void grow(std::size_t capacity) {
    FileBytes::Storage bigger = FileBytes::allocate(capacity);
    if (held() > 0) std::memcpy(bigger.get(), data_.get(), held());
    data_ = std::move(bigger);
    capacity_ = capacity;
  }

  FileBytes::Storage data_;
  std::size_t capacity_ = 0;
  std::size_t size_ = 0;
  std::size_t pos_ = 0;
  std::size_t gapAt_ = 0, gapSize_ = 0;
};

// Leaf `leaf`'s array of the attribute at hand, `size` bytes, its values to be stored by the
// caller's PointValues.
struct Piece {
  std::size_t size = 0;
  std::size_t leaf = 0;
};

// ---- the leaves' buffers ----------------------------------------------------------------------
//
// What Grid<PointDataTree>::writeBuffers() writes (OpenVDB 10, points/PointDataGrid.h and
// Grid.h): a uint16 pass count n, the largest PointDataLeafNode::buffers() of the leaves (2a + 4
// for a attributes), then n passes, each over every leaf in the tree's order (the order of the
// tree's leaf iterator, which is RootNode's and InternalNode's writeBuffers() order):
//   0          each leaf's voxel offsets' compressed size (uint16);
//   1          the attribute descriptor (once, with the first leaf, when every leaf's descriptor
//              is equal) and each leaf's arrays' metadata;
//   2 … a+1    attribute k's page sizes (blosc only; nothing without it);
//   a+2        each leaf's value mask and voxel offsets (blosc-compressed, whatever the file's
//              compression);
//   a+3 … 2a+2 attribute k's values: without blosc each leaf's array as its writeBuffers()
//              writes it; with blosc, every leaf's array bytes in turn go through one
//              compression::PagedOutputStream per attribute, which compresses and writes a page
//              whenever the next array would overflow its 1 MiB (PagedOutputStream::write);
//   2a+3       clean-up, nothing written.
// A paged stream's last page is written when the next pass starts, so an attribute's pages
// (sizes or values) follow each other with nothing in between. Everything but the pages belongs
// to one leaf, and a page to a run of consecutive leaves: leaf ranges and pages are encoded
// apart, in parallel, each by the OpenVDB function the serial writer calls for it, and the file
// is their concatenation in the order above. The arrays without blosc, most of the file, are
// stored from the caller's values as the file is written (their sizes are known in advance,
// so the grid's end offset is too); the rest is made first, then copied into the chunks
// written (DeferredBuffers, EncodedPointsFile::write).

constexpr std::size_t kRangePoints = 16384;  // a leaf range ends once it holds this many points
constexpr std::size_t kRangeLeaves = 64;     // or this many leaves

// The leaves in the tree's order (RootNode's and InternalNode's order: by top node, then by
// internal node, then by leaf, each in Coord order), what their arrays hold (the sample's
// attributes, expanded), and each attribute's bytes a value and metadata record as OpenVDB
// writes it for the sample's array expanded.
struct Leaves {
  const PointLeaves* leaves = nullptr;  // (never null)
  std::vector<std::uint32_t> order;     // the tree's order: leaves->origins[order[l]]
  const PointValues* values = nullptr;  // (never null)
  std::vector<std::size_t> storage;
  std::vector<std::string> metadata;

  std::size_t size() const { return order.size(); }
  std::size_t points(std::size_t l) const { return leaves->counts[order[l]]; }
  const openvdb::Coord& origin(std::size_t l) const { return leaves->origins[order[l]]; }
  const Leaf::NodeMaskType& mask(std::size_t l) const { return leaves->masks[order[l]]; }
  openvdb::PointDataIndex32* voxelEnds(std::size_t l) const {
    return leaves->voxelEnds.get() + std::size_t{order[l]} * Leaf::SIZE;
  }
  const vdbp::AttributeSet& attributes() const { return leaves->sample->attributeSet(); }
  // Leaf l's values of attribute a, stored at `to` by the caller's PointValues.
  void store(std::size_t l, std::size_t a, char* to) const {
    values->store(a, origin(l), points(l), to);
  }
  // The bytes of leaf l's array of attribute a, without blosc's or the flag's.
  std::size_t arrayBytes(std::size_t l, std::size_t a) const { return points(l) * storage[a]; }
};

// The nodes above a leaf: a tree's top nodes (RootNode's children) and the internal nodes
// below them, whose children are leaves.
using TopNode = vdbp::PointDataTree::RootNodeType::ChildNodeType;
using LowerNode = TopNode::ChildNodeType;
static_assert(std::is_same_v<LowerNode::ChildNodeType, Leaf>);
openvdb::Coord topOrigin(const openvdb::Coord& leaf) { return leaf & ~(TopNode::DIM - 1); }
openvdb::Coord lowerOrigin(const openvdb::Coord& leaf) { return leaf & ~(LowerNode::DIM - 1); }

// The leaves at `origins` (ascending) in the tree's order, as indices into `origins`.
std::vector<std::uint32_t> treeOrder(const std::vector<openvdb::Coord>& origins) {
  std::vector<std::uint32_t> order(origins.size());
  for (std::size_t l = 0; l < order.size(); ++l) order[l] = static_cast<std::uint32_t>(l);
  // Stable: leaves of one internal node keep their Coord order.
  std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    const openvdb::Coord &p = origins[a], &q = origins[b];
    if (topOrigin(p) != topOrigin(q)) return topOrigin(p) < topOrigin(q);
    return lowerOrigin(p) < lowerOrigin(q);
  });
  return order;
}

// The first leaf of each range, and the end: a pure function of the leaves, not of the threads.
std::vector<std::size_t> leafRanges(const Leaves& all) {
  std::vector<std::size_t> starts{0};
  std::size_t points = 0;
  for (std::size_t l = 0; l < all.size(); ++l) {
    points += all.points(l);
    if (points >= kRangePoints || l + 1 - starts.back() >= kRangeLeaves) {
      starts.push_back(l + 1);
      points = 0;
    }
  }
  if (starts.back() != all.size()) starts.push_back(all.size());
  return starts;
}

// A stream over `buffer` that carries a copy of the grid's stream metadata as the main stream
// has it while OpenVDB writes the leaves' buffers: the data compression above all, which the
// attribute arrays' metadata and buffers read.
class LeafStream {
 public:
  LeafStream(std::streambuf* buffer, const openvdb::io::StreamMetadata& metadata)
      : metadata_(std::make_shared<openvdb::io::StreamMetadata>(metadata)), out_(buffer) {
    openvdb::io::setStreamMetadataPtr(out_, metadata_, /*transfer=*/true);
  }
  ~LeafStream() { openvdb::io::clearStreamMetadataPtr(out_); }
  LeafStream(const LeafStream&) = delete;
  LeafStream& operator=(const LeafStream&) = delete;
  std::ostream& out() { return out_; }

 private:
  openvdb::io::StreamMetadata::Ptr metadata_;  // before out_: it must outlive the stream's use
  std::ostream out_;
};

// ---- the arrays' records ---------------------------------------------------------------------
//
// TypedAttributeArray::writeMetadata() (points/AttributeArray.h, OpenVDB 10) writes, for an array
// in memory and not transient: its byte count (uint64: 2 + 4 + the array's bytes, for flags and
// size; a paged array's bytes are never compressed here), flags (uint8), serialization flags
// (uint8), size (uint32), and the stride (uint32) only where it is not 1. Only the byte count and
// the size depend on the point count: a leaf's record is the sample's expanded array's with
// those two set to the leaf's.
constexpr std::size_t kMetadataBytesAt = 0, kMetadataSizeAt = 10, kMetadataLength = 14;

std::uint64_t metadataByteCount(std::size_t points, std::size_t storage) {
  return sizeof(openvdb::Int16) + sizeof(openvdb::Index) + points * storage;
}

// Attribute a's record for the sample, written by OpenVDB for a copy of its array expanded.
std::string metadataTemplate(const Leaves& all, std::size_t a,
                             const openvdb::io::StreamMetadata& metadata) {
  const vdbp::AttributeArray::Ptr expanded = all.attributes().getConst(a)->copy();
  expanded->expand(/*fill=*/true);
  std::stringbuf text;
  {
    LeafStream stream(&text, metadata);
    expanded->writeMetadata(stream.out(), /*outputTransient=*/false, /*paged=*/true);
  }
  std::string record = text.str();
  std::uint64_t bytes = 0;
  openvdb::Index size = 0;
  if (record.size() == kMetadataLength) {
    std::memcpy(&bytes, record.data() + kMetadataBytesAt, sizeof bytes);
    std::memcpy(&size, record.data() + kMetadataSizeAt, sizeof size);
  }
  if (record.size() != kMetadataLength || size != 1 ||
      bytes != metadataByteCount(1, all.storage[a])) {
    throw std::logic_error("VDB points: an attribute's metadata is not laid out as foreseen");
  }
  return record;
}

// Leaf l's record of attribute a, as writeMetadata() writes it for the array expanded.
void writeArrayMetadata(const Leaves& all, std::size_t l, std::size_t a, std::ostream& out) {
  char record[kMetadataLength];
  std::memcpy(record, all.metadata[a].data(), kMetadataLength);
  const std::uint64_t bytes = metadataByteCount(all.points(l), all.storage[a]);
  const auto size = static_cast<openvdb::Index>(all.points(l));
  std::memcpy(record + kMetadataBytesAt, &bytes, sizeof bytes);
  std::memcpy(record + kMetadataSizeAt, &size, sizeof size);
  out.write(record, kMetadataLength);
}

// A leaf range's parts of passes 0, 1 and a+2, one after another in `sink`: the offsets' sizes
// end at ends[0], the arrays' metadata at ends[1], the voxel buffers at ends[2].
struct RangeBytes {
  std::unique_ptr<MemorySink> sink;
  std::size_t ends[3] = {};
};

// Pass a+2's record of a leaf (LeafNode::writeBuffers(), with OpenVDB's writeCompressedValues()
// for PointDataIndex32): the value mask, the 16-bit size of the blosc-compressed voxel offsets
// (kUncompressed when blosc did not make them smaller: the offsets follow whole), the bytes.
constexpr std::size_t kValueMaskBytes = sizeof(Leaf::NodeMaskType);
constexpr std::uint16_t kUncompressed = std::numeric_limits<std::uint16_t>::max();
constexpr std::size_t kVoxelOffsetBytes = Leaf::SIZE * sizeof(openvdb::PointDataIndex32);

// Writes the parts of leaves [begin, end) into `range`, each by the call that
// PointDataLeafNode::writeBuffers() makes in its pass; but for pass 0, each leaf's 16-bit size of
// its compressed voxel offsets, which writeCompressedValuesSize() finds by compressing them as
// pass a+2 does: here it is read from pass a+2's record, made first, so each leaf's offsets are
// compressed once. (Where pass a+2 kept them whole, OpenVDB's own call writes the size.)
void encodeLeafRange(const Leaves& all, std::size_t begin, std::size_t end,
                     const openvdb::io::StreamMetadata& metadata, bool toHalf, RangeBytes& range) {
  MemorySink voxels((end - begin) * (kValueMaskBytes + 2 + 1024) + 4096);
  std::vector<std::uint16_t> sizes;
  {
    LeafStream stream(&voxels, metadata);
    for (std::size_t l = begin; l < end; ++l) {
      const std::size_t at = voxels.size();
      // LeafNode::writeBuffers(), the leaf's part of the pass.
      all.mask(l).save(stream.out());
      openvdb::io::writeCompressedValues(stream.out(), all.voxelEnds(l), Leaf::SIZE, all.mask(l),
                                         Leaf::NodeMaskType(), toHalf);
      std::uint16_t size = 0;
      if (voxels.size() >= at + kValueMaskBytes + sizeof size)
        std::memcpy(&size, voxels.data() + at + kValueMaskBytes, sizeof size);
      const std::size_t bytes = size == kUncompressed ? kVoxelOffsetBytes : size;
      if (!stream.out() || voxels.size() != at + kValueMaskBytes + sizeof size + bytes)
        throw std::logic_error("VDB points: a leaf's voxel offsets are not laid out as foreseen");
      sizes.push_back(size);
    }
  }
  range.sink = std::make_unique<MemorySink>((end - begin) * (2 + 128) + voxels.size() + 4096);
  LeafStream stream(range.sink.get(), metadata);
  std::ostream& out = stream.out();
  for (std::size_t l = begin; l < end; ++l) {
    const std::uint16_t size = sizes[l - begin];
    if (size != kUncompressed)
      out.write(reinterpret_cast<const char*>(&size), sizeof size);
    else
      openvdb::io::writeCompressedValuesSize(out, all.voxelEnds(l), Leaf::SIZE);
  }
  range.ends[0] = range.sink->size();
  for (std::size_t l = begin; l < end; ++l) {
    if (l == 0) {
      const std::uint8_t shared = 1;  // one descriptor for every leaf, written with the first
      out.write(reinterpret_cast<const char*>(&shared), sizeof shared);
      all.attributes().writeDescriptor(out, /*outputTransient=*/false);
    }
    for (std::size_t a = 0; a < all.metadata.size(); ++a) writeArrayMetadata(all, l, a, out);
  }
  range.ends[1] = range.sink->size();
  out.write(voxels.data(), static_cast<std::streamsize>(voxels.size()));
  range.ends[2] = range.sink->size();
  if (!out) throw std::runtime_error("cannot encode the VDB points' leaves");
}

// What AttributeArray::writeBuffers() writes without blosc (points/AttributeArray.h) for leaf
// l's array of attribute a expanded (the sample's array, expanded, is neither uniform nor
// transient): a flag byte (0: not compressed) and the values.
std::size_t unpagedBytes(const Leaves& all, std::size_t l, std::size_t a) {
  return 1 + all.arrayBytes(l, a);
}

// Writes attribute `a` of leaves [begin, end) without blosc, as each array's writeBuffers()
// would (PointDataLeafNode::writeBuffers() in pass a+3+k: writePagedBuffers() falls back to it),
// into the `size` bytes at `to`, which unpagedBytes() said they take: each array's flag, then
// its values, stored by the caller's PointValues.
void writeArrays(const Leaves& all, std::size_t begin, std::size_t end, std::size_t a, char* to,
                 std::size_t size) {
  char* const stop = to + size;
  for (std::size_t l = begin; l < end; ++l) {
    *to++ = 0;  // not compressed
    all.store(l, a, to);
    to += all.arrayBytes(l, a);
  }
  if (to != stop)
    throw std::logic_error("VDB points: an attribute array took other than the bytes foreseen");
}

// One page of a paged attribute: the arrays' bytes it gathers, in order, and its two records,
// the size (in the sizes' pass) and the bytes (in the values' pass).
struct Page {
  std::size_t attribute = 0;
  std::vector<Piece> arrays;
  std::size_t bytes = 0;
  std::unique_ptr<MemorySink> values;
  char size[2 * sizeof(int)] = {};
  std::size_t sizeBytes = 0;
};

// Attribute `a`'s pages, as PagedOutputStream::write() cuts them: an array that would take the
// page past compression::PageSize closes it first; an array larger than a page is a page alone.
void cutPages(const Leaves& all, std::size_t a, std::vector<Page>& pages) {
  const auto pageSize = static_cast<std::size_t>(openvdb::compression::PageSize);
  Page page;
  page.attribute = a;
  auto close = [&] {
    if (page.bytes > 0) pages.push_back(std::move(page));
    page = Page();
    page.attribute = a;
  };
  for (std::size_t l = 0; l < all.size(); ++l) {
    const Piece piece{all.arrayBytes(l, a), l};
    const std::size_t bytes = piece.size;
    if (bytes == 0) continue;
    if (bytes > pageSize) {
      close();
      page.arrays.push_back(piece);
      page.bytes = bytes;
      close();
      continue;
    }
    if (page.bytes + bytes > pageSize) close();
    page.arrays.push_back(piece);
    page.bytes += bytes;
  }
  close();
}

// Compresses `page` through a PagedOutputStream of its own (the serial writer's call), and makes
// its size record from the result: (compressed, uncompressed) as two ints when blosc made it
// smaller, else −uncompressed (PagedOutputStream::compressAndWrite() in size-only mode, which
// compresses the same bytes the same way only to count them).
// The arrays' values are stored one after another first, then written at once: the page cuts
// and compresses them as it would the same bytes written array by array.
void encodePage(const Leaves& all, Page& page) {
  const std::size_t a = page.attribute;
  page.values = std::make_unique<MemorySink>(page.bytes);
  std::ostream out(page.values.get());
  openvdb::compression::PagedOutputStream stream(out);
  stream.setSizeOnly(false);
  const std::unique_ptr<char[]> bytes = std::make_unique_for_overwrite<char[]>(page.bytes);
  std::size_t at = 0;
  for (const Piece& array : page.arrays) {
    all.store(array.leaf, a, bytes.get() + at);
    at += array.size;
  }
  stream.write(bytes.get(), static_cast<std::streamsize>(page.bytes));
  stream.flush();
  if (!out) throw std::runtime_error("cannot encode the VDB points' pages");
  const std::size_t written = page.values->size();
  if (written < page.bytes) {
    const int sizes[2] = {static_cast<int>(written), static_cast<int>(page.bytes)};
    std::memcpy(page.size, sizes, sizeof sizes);
    page.sizeBytes = sizeof sizes;
  } else {
    const int uncompressed = -static_cast<int>(page.bytes);
    std::memcpy(page.size, &uncompressed, sizeof uncompressed);
    page.sizeBytes = sizeof uncompressed;
  }
}

// A stretch of the file: bytes made already (`data`), or when `data` is null the unpaged arrays
// of attribute `attribute` of leaves [begin, end), `size` bytes, to be written into place.
struct Part {
  const char* data = nullptr;
  std::size_t size = 0;
  std::size_t attribute = 0, begin = 0, end = 0;
};

// Bytes [from, to) of the `size` bytes of writeArrays(…, begin, end, a, …), at `out`: each leaf's
// array that lies whole in the range written into place, one cut by it through a copy.
void writeArraysSlice(const Leaves& all, std::size_t begin, std::size_t end, std::size_t a,
                      std::size_t size, std::size_t from, std::size_t to, char* out) {
  if (from == 0 && to == size) return writeArrays(all, begin, end, a, out, size);
  std::vector<char> copy;
  std::size_t at = 0;  // where leaf l's array starts
  for (std::size_t l = begin; l < end && at < to; ++l) {
    const std::size_t bytes = unpagedBytes(all, l, a), next = at + bytes;
    if (next > from) {
      if (at >= from && next <= to) {
        writeArrays(all, l, l + 1, a, out + (at - from), bytes);
      } else {
        copy.resize(bytes);
        writeArrays(all, l, l + 1, a, copy.data(), bytes);
        const std::size_t first = std::max(at, from), last = std::min(next, to);
        std::memcpy(out + (first - from), copy.data() + (first - at), last - first);
      }
    }
    at = next;
  }
}

// The leaves' buffers but the pass count, as parts in the file's order: each made already but
// for the unpaged arrays, stored when fill() is called. Owns what the parts point into.
class DeferredBuffers final : public EncodedPointsFile::Deferred {
 public:
  DeferredBuffers(Leaves all, std::vector<RangeBytes> ranges, std::vector<std::vector<Page>> pages,
                  std::vector<Part> parts)
      : all_(std::move(all)),
        ranges_(std::move(ranges)),
        pages_(std::move(pages)),
        parts_(std::move(parts)),
        offsets_(parts_.size() + 1, 0) {
    for (std::size_t p = 0; p < parts_.size(); ++p) offsets_[p + 1] = offsets_[p] + parts_[p].size;
  }
  std::size_t size() const override { return offsets_.back(); }
  void fill(std::size_t from, std::size_t to, char* out) const override {
    // The parts that [from, to) overlaps, the first found by a binary search.
    auto p = static_cast<std::size_t>(std::upper_bound(offsets_.begin(), offsets_.end(), from) -
                                      offsets_.begin());
    for (p = p == 0 ? 0 : p - 1; p < parts_.size() && offsets_[p] < to; ++p) {
      const Part& part = parts_[p];
      const std::size_t first = std::max(from, offsets_[p]), last = std::min(to, offsets_[p + 1]);
      if (first >= last) continue;
      char* const at = out + (first - from);
      const std::size_t inFrom = first - offsets_[p], inTo = last - offsets_[p];
      if (part.data != nullptr) {
        std::memcpy(at, part.data + inFrom, inTo - inFrom);
      } else {
        writeArraysSlice(all_, part.begin, part.end, part.attribute, part.size, inFrom, inTo, at);
      }
    }
  }

 private:
  Leaves all_;
  std::vector<RangeBytes> ranges_;        // (pointed into by parts_)
  std::vector<std::vector<Page>> pages_;  // (pointed into by parts_)
  std::vector<Part> parts_;
  std::vector<std::size_t> offsets_;
};

// The arrays' sizes and metadata records, from the sample (PointLeaves::sample).
void describeArrays(Leaves& all, const openvdb::io::StreamMetadata& metadata) {
  const vdbp::AttributeSet& set = all.attributes();
  for (std::size_t a = 0; a < set.size(); ++a) {
    const vdbp::AttributeArray& array = *set.getConst(a);
    if (array.stride() != 1 || !array.hasConstantStride())
      throw std::logic_error("VDB points: a sample array with a stride");
    if (!array.isUniform() || array.isTransient() || array.size() != 1 || !array.isDataLoaded())
      throw std::logic_error("VDB points: a sample array not uniform and of one point");
    all.storage.push_back(array.storageTypeSize());
  }
  for (std::size_t a = 0; a < set.size(); ++a)
    all.metadata.push_back(metadataTemplate(all, a, metadata));
}

// What Grid<PointDataTree>::writeBuffers() writes for `leaves` (in the tree's order `order`) after
// the pass count, encoded in parallel with the stream metadata `metadata` but for the parts left
// to fill() (DeferredBuffers); null where there is no leaf (two bytes that OpenVDB writes as
// fast).
std::unique_ptr<DeferredBuffers> encodeBuffers(const PointLeaves& leaves,
                                               const std::vector<std::uint32_t>& order, bool toHalf,
                                               const PointValues& values,
                                               const openvdb::io::StreamMetadata::Ptr& metadata) {
  if (leaves.size() == 0) return nullptr;
  Leaves all;
  all.leaves = &leaves;
  all.order = order;
  all.values = &values;
  describeArrays(all, *metadata);

  const std::size_t attributes = all.attributes().size();
  const bool paged = (metadata->compression() & openvdb::io::COMPRESS_BLOSC) != 0;
  const std::vector<std::size_t> starts = leafRanges(all);
  const std::size_t ranges = starts.size() - 1;
  std::vector<RangeBytes> rangeBytes(ranges);
  std::vector<std::vector<Page>> pages(paged ? attributes : 0);
  for (std::size_t a = 0; a < pages.size(); ++a) cutPages(all, a, pages[a]);
  std::vector<Page*> allPages;
  for (std::vector<Page>& attributePages : pages)
    for (Page& page : attributePages) allPages.push_back(&page);

  // Leaf ranges then pages, one task each, one loop so that neither waits for the other.
  par::parallel_for(tbb::blocked_range<std::size_t>(0, ranges + allPages.size(), 1),
                    [&](const tbb::blocked_range<std::size_t>& tasks) {
                      for (std::size_t t = tasks.begin(); t < tasks.end(); ++t) {
                        if (t < ranges) {
                          encodeLeafRange(all, starts[t], starts[t + 1], *metadata, toHalf,
                                          rangeBytes[t]);
                        } else {
                          encodePage(all, *allPages[t - ranges]);
                        }
                      }
                    });

  // The file's order: pass by pass, range by range (attribute by attribute, page by page).
  std::vector<Part> parts;
  auto rangePart = [&](std::size_t pass) {
    for (const RangeBytes& r : rangeBytes) {
      const std::size_t from = pass == 0 ? 0 : r.ends[pass - 1];
      parts.push_back(Part{r.sink->data() + from, r.ends[pass] - from});
    }
  };
  rangePart(0);
  rangePart(1);
  for (const std::vector<Page>& attributePages : pages)
    for (const Page& page : attributePages) parts.push_back(Part{page.size, page.sizeBytes});
  rangePart(2);
  for (const std::vector<Page>& attributePages : pages) {
    for (const Page& page : attributePages)
      parts.push_back(Part{page.values->data(), page.values->size()});
  }
  if (!paged) {
    for (std::size_t a = 0; a < attributes; ++a) {
      for (std::size_t r = 0; r < ranges; ++r) {
        Part part{nullptr, 0, a, starts[r], starts[r + 1]};
        for (std::size_t l = part.begin; l < part.end; ++l) part.size += unpagedBytes(all, l, a);
        parts.push_back(part);
      }
    }
  }
  return std::make_unique<DeferredBuffers>(std::move(all), std::move(rangeBytes), std::move(pages),
                                           std::move(parts));
}

// The background value of every points tree written here, where the topology's writer points
// the stream (RootNode::writeTopology()): the leaves' and internal nodes' compression reads it.
const openvdb::PointDataIndex32 kBackground{0};

// encodeBuffers() begun ahead, on another thread, while this one goes on: Archive::write() has
// set the stream's metadata for the grid by the time it makes the grid's statistics
// (ParallelBuffersGrid::copyGrid()), and then writes the header and topology on this thread
// alone, which the leaves' buffers need not wait for. What is made is used only if the metadata
// is the same when the buffers are written.
class BuffersAhead {
 public:
  explicit BuffersAhead(std::ios_base& os) : os_(os) {}
  ~BuffersAhead() {
    try {
      group_.wait();
    } catch (...) {  // (the write failed before it took the buffers: it throws already)
    }
  }
  BuffersAhead(const BuffersAhead&) = delete;
  BuffersAhead& operator=(const BuffersAhead&) = delete;

  // Begins encodeBuffers() with the stream's metadata as it is now; once only.
  void start(const PointLeaves& leaves, const std::vector<std::uint32_t>& order, bool toHalf,
             const PointValues& values) {
    const openvdb::io::StreamMetadata::Ptr now = openvdb::io::getStreamMetadataPtr(os_);
    if (started_ || !now) return;
    started_ = true;
    metadata_ = std::make_shared<openvdb::io::StreamMetadata>(*now);
    // As the topology's writer will have set it (writeTopology()).
    metadata_->setBackgroundPtr(&kBackground);
    madeFor_ = metadata_->str();
    group_.run([this, &leaves, &order, toHalf, &values] {
      buffers_ = encodeBuffers(leaves, order, toHalf, values, metadata_);
    });
  }
  // What start() made, once made (an exception it threw is thrown here), when it was made with
  // stream metadata like `metadata`; null otherwise, or when it was not started.
  std::unique_ptr<DeferredBuffers> take(const openvdb::io::StreamMetadata& metadata) {
    if (!started_) return nullptr;
    {
      const profile::ParallelScope parallel;
      group_.wait();
    }
    started_ = false;
    if (metadata.str() != madeFor_ || metadata.backgroundPtr() != metadata_->backgroundPtr())
      return nullptr;
    return std::move(buffers_);
  }

 private:
  std::ios_base& os_;  // (getStreamMetadataPtr() takes it non-const)
  tbb::task_group group_;
  bool started_ = false;
  openvdb::io::StreamMetadata::Ptr metadata_;
  std::string madeFor_;
  std::unique_ptr<DeferredBuffers> buffers_;
};

// Writes what Grid<PointDataTree>::writeBuffers(os) writes for `leaves`, encoded in parallel but
// for the parts left to `deferred` (DeferredBuffers: `os` skips their bytes). The buffers are
// those `ahead` made, where it made them for this stream. At least one leaf.
void writeBuffersInParallel(const PointLeaves& leaves, const std::vector<std::uint32_t>& order,
                            bool toHalf, const PointValues& values, std::ostream& os,
                            BuffersAhead* ahead,
                            std::unique_ptr<EncodedPointsFile::Deferred>& deferred) {
  auto* const sink = dynamic_cast<MemorySink*>(os.rdbuf());
  const openvdb::io::StreamMetadata::Ptr metadata = openvdb::io::getStreamMetadataPtr(os);
  std::unique_ptr<DeferredBuffers> buffers =
      ahead != nullptr && metadata ? ahead->take(*metadata) : nullptr;
  if (sink == nullptr) throw std::logic_error("VDB points: leaves written to a stream not ours");
  if (!metadata) throw std::runtime_error("VDB points: a stream without OpenVDB's metadata");
  if (!buffers) buffers = encodeBuffers(leaves, order, toHalf, values, metadata);  // (leaves)
  const auto passes = static_cast<std::uint16_t>(leaves.sample->buffers());
  os.write(reinterpret_cast<const char*>(&passes), sizeof passes);
  sink->skip(buffers->size());
  deferred = std::move(buffers);
}

// ---- the topology and the statistics ----------------------------------------------------------

// The bounding box of the leaves' active voxels, as Tree::evalActiveVoxelBoundingBox() finds it
// for a points tree (no active tiles, and a leaf only where some voxel holds points), from each
// leaf's mask words: word x of a leaf's mask holds its voxels (x, y, z) at bit 8y + z
// (LeafNode::coordToOffset()). OpenVDB visits each active voxel.
openvdb::CoordBBox activeVoxelBox(const PointLeaves& leaves) {
  static_assert(Leaf::NodeMaskType::WORD_COUNT == Leaf::DIM && Leaf::DIM * Leaf::DIM == 64);
  openvdb::CoordBBox box;
  for (std::size_t l = 0; l < leaves.size(); ++l) {
    const Leaf::NodeMaskType& mask = leaves.masks[l];
    std::uint64_t any = 0;  // the (y, z) that some x holds
    int firstX = -1, lastX = -1;
    for (openvdb::Index x = 0; x < Leaf::DIM; ++x) {
      const std::uint64_t word = mask.template getWord<std::uint64_t>(x);
      if (word == 0) continue;
      if (firstX < 0) firstX = static_cast<int>(x);
      lastX = static_cast<int>(x);
      any |= word;
    }
    if (any == 0) continue;
    unsigned ys = 0, zs = 0;  // bit y (z): some active voxel has that y (z)
    for (unsigned y = 0; y < Leaf::DIM; ++y) {
      const auto zsOfY = static_cast<unsigned>((any >> (Leaf::DIM * y)) & 0xffu);
      ys |= unsigned{zsOfY != 0} << y;
      zs |= zsOfY;
    }
    const auto low = [](unsigned bits) { return std::countr_zero(bits); };
    const auto high = [](unsigned bits) { return std::bit_width(bits) - 1; };
    box.expand(leaves.origins[l] + openvdb::Coord(firstX, low(ys), low(zs)));
    box.expand(leaves.origins[l] + openvdb::Coord(lastX, high(ys), high(zs)));
  }
  return box;
}

// The active voxels, as Tree::activeVoxelCount() counts them.
openvdb::Index64 activeVoxelCount(const PointLeaves& leaves) {
  openvdb::Index64 count = 0;
  for (const Leaf::NodeMaskType& mask : leaves.masks) count += mask.countOn();
  return count;
}

// Where the leaves of each internal node begin in the tree's order `order`, each list ended by
// order.size(): the top nodes' (RootNode's children) and the nodes' below them.
struct NodeStarts {
  std::vector<std::size_t> top, lower;
};
NodeStarts nodeStarts(const PointLeaves& leaves, const std::vector<std::uint32_t>& order) {
  NodeStarts starts;
  for (std::size_t k = 0; k < order.size(); ++k) {
    const openvdb::Coord& origin = leaves.origins[order[k]];
    const openvdb::Coord* const before = k == 0 ? nullptr : &leaves.origins[order[k - 1]];
    if (!before || topOrigin(origin) != topOrigin(*before)) starts.top.push_back(k);
    if (!before || lowerOrigin(origin) != lowerOrigin(*before)) starts.lower.push_back(k);
  }
  starts.top.push_back(order.size());
  starts.lower.push_back(order.size());
  return starts;
}

// What tools::memUsage() (Tree::memUsage()) counts for the tree of `leaves` (OpenVDB 10,
// tools/Count.h's MemUsageOp): the tree and its root node, each internal node's values and
// masks and origin, and each leaf's memUsage(): the sample's with its arrays expanded, each
// array's values a point more or fewer by its storage.
openvdb::Index64 memUsage(const PointLeaves& leaves, const NodeStarts& nodes) {
  const auto nodeBytes = []<typename Node>(std::type_identity<Node>) {
    return openvdb::Index64{Node::NUM_VALUES * sizeof(typename Node::UnionType)} +
           2 * typename Node::NodeMaskType().memUsage() + sizeof(openvdb::Coord);
  };
  const vdbp::AttributeSet& set = leaves.sample->attributeSet();
  openvdb::Index64 perPoint = 0;
  for (std::size_t a = 0; a < set.size(); ++a) perPoint += set.getConst(a)->storageTypeSize();
  openvdb::Index64 points = 0;
  for (const std::size_t count : leaves.counts) points += count;
  return sizeof(vdbp::PointDataTree) + sizeof(vdbp::PointDataTree::RootNodeType) +
         (nodes.top.size() - 1) * nodeBytes(std::type_identity<TopNode>()) +
         (nodes.lower.size() - 1) * nodeBytes(std::type_identity<LowerNode>()) +
         leaves.size() * leaves.sample->memUsage() + (points - leaves.size()) * perPoint;
}

// What an internal node of type Node writes of its values (InternalNode::writeTopology()), the
// same for every internal node of a points tree: all its values the background, none active,
// so OpenVDB's compression of them (io::writeCompressedValues()) depends on neither its child
// mask nor anything else of it. Made once a frame with the stream's own settings.
template <typename Node>
std::string internalValues(const openvdb::io::StreamMetadata& metadata, bool toHalf) {
  std::stringbuf text;
  {
    LeafStream stream(&text, metadata);
    std::vector<openvdb::PointDataIndex32> values(Node::NUM_VALUES, kBackground);
    const typename Node::NodeMaskType none;
    openvdb::io::writeCompressedValues(stream.out(), values.data(), Node::NUM_VALUES, none, none,
                                       toHalf);
    if (!stream.out()) throw std::runtime_error("cannot encode the VDB points' topology");
  }
  return text.str();
}

// What Tree<PointDataTree>::writeTopology() writes for `leaves` (OpenVDB 10: TreeBase's buffer
// count, then RootNode's, InternalNode's and LeafNode's writeTopology()), in the tree's order
// `order`, whose internal nodes begin at `nodes`: the background value, no tile and the top
// nodes, each its origin, masks, values and children, each leaf its value mask. Points the
// stream at the background, as RootNode's does.
void writeTopology(std::ostream& os, const PointLeaves& leaves,
                   const std::vector<std::uint32_t>& order, const NodeStarts& nodes, bool toHalf) {
  const auto put = [&os](const auto& value) {
    os.write(reinterpret_cast<const char*>(&value), sizeof value);
  };
  put(std::int32_t{1});
  put(kBackground);  // (toHalf leaves an integer as it is)
  openvdb::io::setGridBackgroundValuePtr(os, &kBackground);
  const openvdb::io::StreamMetadata::Ptr metadata = openvdb::io::getStreamMetadataPtr(os);
  if (!metadata) throw std::runtime_error("VDB points: a stream without OpenVDB's metadata");
  const std::string topValues = internalValues<TopNode>(*metadata, toHalf);
  const std::string lowerValues = internalValues<LowerNode>(*metadata, toHalf);
  put(openvdb::Index{0});                                  // tiles
  put(static_cast<openvdb::Index>(nodes.top.size() - 1));  // children
  // An internal node whose children hold the leaves order[begin, end): its masks and values.
  const auto writeNode = [&]<typename Node>(std::type_identity<Node>, std::size_t begin,
                                            std::size_t end, const std::string& values) {
    typename Node::NodeMaskType children;
    for (std::size_t k = begin; k < end; ++k)
      children.setOn(Node::coordToOffset(leaves.origins[order[k]]));
    children.save(os);
    typename Node::NodeMaskType().save(os);  // no active tile
    os.write(values.data(), static_cast<std::streamsize>(values.size()));
  };
  std::size_t lower = 0;  // in nodes.lower
  for (std::size_t t = 0; t + 1 < nodes.top.size(); ++t) {
    const openvdb::Coord top = topOrigin(leaves.origins[order[nodes.top[t]]]);
    os.write(reinterpret_cast<const char*>(top.asPointer()), 3 * sizeof(openvdb::Int32));
    writeNode(std::type_identity<TopNode>(), nodes.top[t], nodes.top[t + 1], topValues);
    // (A top node's leaves begin a lower node's.)
    for (; nodes.lower[lower] < nodes.top[t + 1]; ++lower) {
      const std::size_t begin = nodes.lower[lower], end = nodes.lower[lower + 1];
      writeNode(std::type_identity<LowerNode>(), begin, end, lowerValues);
      for (std::size_t k = begin; k < end; ++k) leaves.masks[order[k]].save(os);
    }
  }
}

// The grid as Archive::write() sees it: the leaves' grid (encodePointsFile's `grid`, whose
// metadata and transform it copies) with the tree of `leaves`, which it writes
// itself: its topology (writeTopology() above), its statistics and its leaves' buffers
// (writeBuffersInParallel()). Archive::write() calls the virtual GridBase::writeTopology() and
// writeBuffers() in turn, then patches the grid's end offset into its descriptor itself; the
// statistics it records in the file (file_bbox_min/max, file_mem_bytes, file_voxel_count) come
// from the shallow copy it makes (copyGrid() const, which starts `ahead`).
// A GridBase of its own, not a PointDataGrid: a subclass would instantiate every virtual member
// of Grid<PointDataTree> and Tree<PointDataTree> here (fields/vdb/RegisteredGrid.h says what that
// costs). Without leaves, everything is the leaves' grid's own. What Archive::write() does not
// call on a grid it writes (reading, changing the tree) is refused.
class ParallelBuffersGrid final : public openvdb::GridBase {
 public:
  // `order` and `nodes`: the leaves' tree order (treeOrder()) and its nodes (nodeStarts()).
  ParallelBuffersGrid(const vdbp::PointDataGrid& grid, const PointLeaves& leaves,
                      const std::vector<std::uint32_t>& order, const NodeStarts& nodes,
                      const PointValues& values, BuffersAhead* ahead,
                      std::unique_ptr<EncodedPointsFile::Deferred>* deferred)
      : openvdb::GridBase(grid),  // (its metadata and transform, copied)
        grid_(&grid),
        leaves_(&leaves),
        order_(&order),
        nodes_(&nodes),
        values_(&values),
        ahead_(ahead),
        deferred_(deferred) {
    if (!grid.constTree().empty())
      throw std::logic_error("VDB points: the leaves' grid holds leaves of its own");
  }
  // A shallow copy.
  ParallelBuffersGrid(const ParallelBuffersGrid& grid, openvdb::ShallowCopy)
      : openvdb::GridBase(grid),
        grid_(grid.grid_),
        leaves_(grid.leaves_),
        order_(grid.order_),
        nodes_(grid.nodes_),
        values_(grid.values_),
        ahead_(grid.ahead_),
        deferred_(grid.deferred_) {}

  void writeTopology(std::ostream& os) const override {
    if (!hasLeaves()) return base().writeTopology(os);
    tickfx::io::writeTopology(os, *leaves_, *order_, *nodes_, saveFloatAsHalf());
  }
  void writeBuffers(std::ostream& os) const override {
    if (!hasLeaves()) return base().writeBuffers(os);
    writeBuffersInParallel(*leaves_, *order_, saveFloatAsHalf(), *values_, os, ahead_, *deferred_);
  }
  openvdb::Index64 memUsage() const override {
    return hasLeaves() ? tickfx::io::memUsage(*leaves_, *nodes_) : base().memUsage();
  }
  openvdb::Index64 activeVoxelCount() const override {
    return hasLeaves() ? tickfx::io::activeVoxelCount(*leaves_) : base().activeVoxelCount();
  }
  openvdb::CoordBBox evalActiveVoxelBoundingBox() const override {
    return hasLeaves() ? activeVoxelBox(*leaves_) : base().evalActiveVoxelBoundingBox();
  }
  openvdb::Coord evalActiveVoxelDim() const override {
    return hasLeaves() ? activeVoxelBox(*leaves_).dim() : base().evalActiveVoxelDim();
  }
  bool empty() const override { return !hasLeaves(); }
  openvdb::GridBase::Ptr copyGrid() override {
    return std::make_shared<ParallelBuffersGrid>(*this, openvdb::ShallowCopy());
  }
  openvdb::GridBase::ConstPtr copyGrid() const override {
    if (ahead_ != nullptr && hasLeaves())
      ahead_->start(*leaves_, *order_, saveFloatAsHalf(), *values_);
    return std::make_shared<ParallelBuffersGrid>(*this, openvdb::ShallowCopy());
  }

  // The leaves' grid's own, through its virtual members.
  openvdb::Name type() const override { return base().type(); }
  openvdb::Name valueType() const override { return base().valueType(); }
  openvdb::TreeBase::ConstPtr constBaseTreePtr() const override {
    return base().constBaseTreePtr();
  }
  bool isTreeUnique() const override { return base().isTreeUnique(); }
  void print(std::ostream& os, int verboseLevel) const override { base().print(os, verboseLevel); }

  // Not for a grid being written.
  openvdb::GridBase::Ptr copyGridWithNewTree() const override { refuse(); }
  openvdb::GridBase::ConstPtr copyGridReplacingMetadata(const openvdb::MetaMap&) const override {
    refuse();
  }
  openvdb::GridBase::ConstPtr copyGridReplacingTransform(
      openvdb::math::Transform::Ptr) const override {
    refuse();
  }
  openvdb::GridBase::ConstPtr copyGridReplacingMetadataAndTransform(
      const openvdb::MetaMap&, openvdb::math::Transform::Ptr) const override {
    refuse();
  }
  openvdb::GridBase::Ptr deepCopyGrid() const override { refuse(); }
  void setTree(openvdb::TreeBase::Ptr) override { refuse(); }
  void newTree() override { refuse(); }
  void clear() override { refuse(); }
  void pruneGrid(float) override { refuse(); }
  void clip(const openvdb::CoordBBox&) override { refuse(); }
  void readTopology(std::istream&) override { refuse(); }
  void readBuffers(std::istream&) override { refuse(); }
  void readBuffers(std::istream&, const openvdb::CoordBBox&) override { refuse(); }
  void readNonresidentBuffers() const override { refuse(); }

 private:
  const openvdb::GridBase& base() const { return *grid_; }
  bool hasLeaves() const { return leaves_->size() > 0; }
  [[noreturn]] static void refuse() {
    throw std::logic_error("VDB points: a grid being written was asked to change or copy");
  }

  const vdbp::PointDataGrid* grid_;          // (never null; outlives the write)
  const PointLeaves* leaves_;                // (never null)
  const std::vector<std::uint32_t>* order_;  // (never null)
  const NodeStarts* nodes_;                  // (never null)
  const PointValues* values_ = nullptr;      // (never null)
  BuffersAhead* ahead_ = nullptr;
  std::unique_ptr<EncodedPointsFile::Deferred>* deferred_;  // where writeBuffers() leaves them
};

// Archive::write(), protected in OpenVDB, with File::write()'s seekable stream.
class PointsArchive final : public openvdb::io::Archive {
 public:
  explicit PointsArchive(std::uint32_t compression) { setCompression(compression); }
  // Not named write(): that would hide Archive's virtual write(grids, metadata).
  void writeSeekable(std::ostream& os, const openvdb::GridCPtrVec& grids) const {
    Archive::write(os, grids, /*seekable=*/true);
  }
};

}  // namespace

EncodedPointsFile::EncodedPointsFile(FileBytes known, std::size_t deferredAt,
                                     std::unique_ptr<Deferred> deferred)
    : known_(std::move(known)), at_(deferredAt), deferred_(std::move(deferred)) {
  if (at_ > known_.size()) throw std::logic_error("EncodedPointsFile: deferred bytes past the end");
}

EncodedPointsFile::~EncodedPointsFile() = default;

std::size_t EncodedPointsFile::size() const {
  return known_.size() + (deferred_ ? deferred_->size() : 0);
}

namespace {

// The file is made and written in chunks of this many bytes (the last shorter): small enough to
// stay in the cache from being made to being copied by the kernel, large enough that a write()
// call's cost is nothing beside the copy, and a multiple of the page cache's large folios.
constexpr std::size_t kChunkBytes = std::size_t{512} << 10;

// Chunk `c` of a file of `size` bytes: [first, second).
std::pair<std::size_t, std::size_t> chunkBytes(std::size_t c, std::size_t size) {
  return {c * kChunkBytes, std::min(size, (c + 1) * kChunkBytes)};
}
std::size_t chunkCount(std::size_t size) { return (size + kChunkBytes - 1) / kChunkBytes; }

}  // namespace

void EncodedPointsFile::fill(std::size_t from, std::size_t to, char* out) const {
  const std::size_t deferred = deferred_ ? deferred_->size() : 0, end = at_ + deferred;
  // The known bytes before the deferred ones, the deferred ones, the known ones after.
  const auto copy = [&](std::size_t first, std::size_t last, const auto& put) {
    first = std::max(first, from);
    last = std::min(last, to);
    if (first < last) put(first, last, out + (first - from));
  };
  copy(0, at_,
       [&](std::size_t a, std::size_t b, char* o) { std::memcpy(o, known_.data() + a, b - a); });
  copy(at_, end,
       [&](std::size_t a, std::size_t b, char* o) { deferred_->fill(a - at_, b - at_, o); });
  copy(end, end + (known_.size() - at_), [&](std::size_t a, std::size_t b, char* o) {
    std::memcpy(o, known_.data() + (a - deferred), b - a);
  });
}

FileBytes EncodedPointsFile::bytes() const {
  FileBytes file(FileBytes::allocate(size()), size());
  par::parallel_for(tbb::blocked_range<std::size_t>(0, chunkCount(size()), 1),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t c = r.begin(); c < r.end(); ++c) {
                        const auto [from, to] = chunkBytes(c, size());
                        fill(from, to, file.data() + from);
                      }
                    });
  return file;
}

void EncodedPointsFile::write(std::ostream& out) const {
  const profile::ParallelScope parallel;
  const std::size_t size = this->size(), chunks = chunkCount(size);
  const auto threads = static_cast<std::size_t>(tbb::this_task_arena::max_concurrency());
  // Chunk c is made into slot c % slots once chunk c − slots is written: made by whichever
  // thread claims it first, written by this one, in order. Every thread makes the next chunk
  // while a slot is free; this one, copying into the kernel one chunk after another, makes one
  // only while the next it writes is being made (waiting then left the kernel idle some 3 ms a
  // frame of 10⁶ points on 2 threads). A pipeline whose threads each made and wrote (TBB's) left
  // the kernel idle while one thread made the positions' chunks. With one thread, this one makes
  // each chunk before writing it, into the one slot, which stays in cache.
  const std::size_t slots = threads == 1 ? 1 : std::max<std::size_t>(8, 2 * threads);
  const FileBytes::Storage room = FileBytes::allocate(slots * kChunkBytes);
  std::atomic<std::size_t> claimed{0}, written{0};
  const std::unique_ptr<std::atomic<bool>[]> made = std::make_unique<std::atomic<bool>[]>(chunks);
  std::atomic<bool> stop{false};
  const auto makeChunk = [&](std::size_t c) {
    const auto [from, to] = chunkBytes(c, size);
    fill(from, to, room.get() + (c % slots) * kChunkBytes);
    made[c].store(true, std::memory_order_release);
  };
  // Claims the next chunk and makes it, where its slot is free.
  const auto claimAndMake = [&] {
    std::size_t c = claimed.load(std::memory_order_relaxed);
    while (c < chunks && c < written.load(std::memory_order_acquire) + slots) {
      if (claimed.compare_exchange_weak(c, c + 1, std::memory_order_relaxed)) {
        makeChunk(c);
        return true;
      }
    }
    return false;
  };
  tbb::task_group makers;
  std::exception_ptr failure;
  std::mutex failureLock;
  const auto fail = [&] {
    const std::lock_guard lock(failureLock);
    if (!failure) failure = std::current_exception();
    stop.store(true, std::memory_order_release);
  };
  for (std::size_t t = 1; t < threads; ++t) {
    makers.run([&] {
      try {
        while (!stop.load(std::memory_order_acquire)) {
          if (claimAndMake()) continue;
          if (claimed.load(std::memory_order_relaxed) >= chunks) break;
          std::this_thread::yield();
        }
      } catch (...) {
        fail();
      }
    });
  }
  try {
    for (std::size_t c = 0; c < chunks && !stop.load(std::memory_order_acquire); ++c) {
      while (!made[c].load(std::memory_order_acquire) && !stop.load(std::memory_order_acquire)) {
        if (!claimAndMake()) std::this_thread::yield();  // (chunk c is being made)
      }
      if (stop.load(std::memory_order_acquire)) break;
      const auto [from, to] = chunkBytes(c, size);
      if (out)
        out.write(room.get() + (c % slots) * kChunkBytes, static_cast<std::streamsize>(to - from));
      written.store(c + 1, std::memory_order_release);
    }
  } catch (...) {
    fail();
  }
  stop.store(true, std::memory_order_release);
  makers.wait();
  if (failure) std::rethrow_exception(failure);
}

EncodedPointsFile encodePointsFile(const vdbp::PointDataGrid& grid, const PointLeaves& leaves,
                                   std::uint32_t compression, const PointValues& values,
                                   std::size_t expectedBytes) {
  std::unique_ptr<EncodedPointsFile::Deferred> deferred;
  MemorySink sink(expectedBytes);
  std::ostream os(&sink);
  const std::vector<std::uint32_t> order = treeOrder(leaves.origins);
  const NodeStarts nodes = nodeStarts(leaves, order);
  BuffersAhead ahead(os);  // (after `order`, which it reads until it is destroyed)
  const openvdb::GridCPtrVec grids{std::make_shared<const ParallelBuffersGrid>(
      grid, leaves, order, nodes, values, &ahead, &deferred)};
  PointsArchive(compression).writeSeekable(os, grids);
  if (!os) throw std::runtime_error("cannot encode the VDB points grid");
  const std::size_t at = deferred ? sink.gapAt() : sink.held();
  return EncodedPointsFile(std::move(sink).release(), at, std::move(deferred));
}

std::string encodePointsFileSerially(const vdbp::PointDataGrid::ConstPtr& grid,
                                     std::uint32_t compression, std::size_t expectedBytes) {
  std::string room;
  room.reserve(expectedBytes);
  std::ostringstream os(std::move(room), std::ios::binary);
  PointsArchive(compression).writeSeekable(os, openvdb::GridCPtrVec{grid});
  if (!os) throw std::runtime_error("cannot encode the VDB points grid");
  return std::move(os).str();
}

}  // namespace tickfx::io
