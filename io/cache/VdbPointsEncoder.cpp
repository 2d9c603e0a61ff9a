#include "io/cache/VdbPointsEncoder.h"

#include <openvdb/io/Archive.h>
#include <openvdb/io/io.h>
#include <openvdb/openvdb.h>
#include <openvdb/points/PointDataGrid.h>
#include <openvdb/points/StreamCompression.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#if defined(__linux__)
#include <sys/mman.h>
#endif

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <ios>
#include <memory>
#include <new>
#include <ostream>
#include <sstream>
#include <stdexcept>
#include <streambuf>
#include <string>
#include <utility>
#include <vector>

#include "io/util/ProfiledTbb.h"

namespace tickfx::io {

void FileBytes::Free::operator()(char* p) const { std::free(p); }

FileBytes::Storage FileBytes::allocate(std::size_t size) {
  constexpr std::size_t kHugePage = std::size_t{2} << 20;
  void* p = nullptr;
  if (size >= kHugePage) {
    const std::size_t rounded = (size + kHugePage - 1) / kHugePage * kHugePage;
    p = std::aligned_alloc(kHugePage, rounded);
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    if (p != nullptr) ::madvise(p, rounded, MADV_HUGEPAGE);  // a hint: its failure changes nothing
#endif
  } else {
    p = std::malloc(std::max<std::size_t>(size, 1));
  }
  if (p == nullptr) throw std::bad_alloc();
  return Storage(static_cast<char*>(p));
}

namespace {

namespace vdbp = openvdb::points;
using Leaf = vdbp::PointDataTree::LeafNodeType;

// ---- memory as a stream -----------------------------------------------------------------------

// An output stream buffer over memory that grows, with what Archive::write() asks of a stream:
// writes, tellp, seekp back to patch what it wrote (a grid's offsets), seekp to the end; and
// append(), a stretch at the end handed out to be filled by other means (several threads).
// Unbuffered: every write goes to xsputn() or overflow(), which copy it into place.
class MemorySink final : public std::streambuf {
 public:
  explicit MemorySink(std::size_t capacity) { grow(std::max<std::size_t>(capacity, 64)); }

  /// Makes room for `n` bytes at the end (the put position must be there), moves the put
  /// position past them and returns where they start; the caller writes them.
  char* append(std::size_t n) {
    if (pos_ != size_) throw std::logic_error("MemorySink::append away from the end");
    if (size_ + n > capacity_) grow(size_ + n);
    char* at = data_.get() + size_;
    size_ += n;
    pos_ = size_;
    return at;
  }
  const char* data() const { return data_.get(); }
  std::size_t size() const { return size_; }
  FileBytes release() && { return FileBytes(std::move(data_), size_); }

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
    if (pos_ + n > capacity_) grow(std::max(pos_ + n, 2 * capacity_));
    std::memcpy(data_.get() + pos_, s, n);
    pos_ += n;
    size_ = std::max(size_, pos_);
  }
  // Capacity `capacity`, keeping what is written.
  void grow(std::size_t capacity) {
    FileBytes::Storage bigger = FileBytes::allocate(capacity);
    if (size_ > 0) std::memcpy(bigger.get(), data_.get(), size_);
    data_ = std::move(bigger);
    capacity_ = capacity;
  }

  FileBytes::Storage data_;
  std::size_t capacity_ = 0;
  std::size_t size_ = 0;
  std::size_t pos_ = 0;
};

// A stretch of bytes of the file, in memory owned elsewhere.
struct Piece {
  const char* data = nullptr;
  std::size_t size = 0;
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
// written straight into place (their sizes are known in advance); the rest is made first, then
// copied there.

constexpr std::size_t kRangePoints = 16384;  // a leaf range ends once it holds this many points
constexpr std::size_t kRangeLeaves = 64;     // or this many leaves

// The first leaf of each range, and the end: a pure function of the grid, not of the threads.
std::vector<std::size_t> leafRanges(const std::vector<const Leaf*>& leaves) {
  std::vector<std::size_t> starts{0};
  std::size_t points = 0;
  for (std::size_t l = 0; l < leaves.size(); ++l) {
    points += leaves[l]->pointCount();
    if (points >= kRangePoints || l + 1 - starts.back() >= kRangeLeaves) {
      starts.push_back(l + 1);
      points = 0;
    }
  }
  if (starts.back() != leaves.size()) starts.push_back(leaves.size());
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

// A leaf range's parts of passes 0, 1 and a+2, one after another in `sink`: the offsets' sizes
// end at ends[0], the arrays' metadata at ends[1], the voxel buffers at ends[2].
struct RangeBytes {
  std::unique_ptr<MemorySink> sink;
  std::size_t ends[3] = {};
};

// Writes the parts of leaves [begin, end) into `range`, each by the call that
// PointDataLeafNode::writeBuffers() makes in its pass.
void encodeLeafRange(const std::vector<const Leaf*>& leaves, std::size_t begin, std::size_t end,
                     const openvdb::io::StreamMetadata& metadata, bool toHalf, RangeBytes& range) {
  range.sink = std::make_unique<MemorySink>((end - begin) * (2 * 1024 + 128) + 4096);
  LeafStream stream(range.sink.get(), metadata);
  std::ostream& out = stream.out();
  for (std::size_t l = begin; l < end; ++l)
    openvdb::io::writeCompressedValuesSize(out, leaves[l]->buffer().data(), Leaf::SIZE);
  range.ends[0] = range.sink->size();
  for (std::size_t l = begin; l < end; ++l) {
    const vdbp::AttributeSet& set = leaves[l]->attributeSet();
    if (l == 0) {
      const std::uint8_t shared = 1;  // one descriptor for every leaf, written with the first
      out.write(reinterpret_cast<const char*>(&shared), sizeof shared);
      set.writeDescriptor(out, /*outputTransient=*/false);
    }
    set.writeMetadata(out, /*outputTransient=*/false, /*paged=*/true);
  }
  range.ends[1] = range.sink->size();
  for (std::size_t l = begin; l < end; ++l)
    static_cast<const Leaf::BaseLeaf&>(*leaves[l]).writeBuffers(out, toHalf);
  range.ends[2] = range.sink->size();
  if (!out) throw std::runtime_error("cannot encode the VDB points' leaves");
}

// What AttributeArray::writeBuffers() writes for `array` without blosc (points/AttributeArray.h):
// nothing for a transient array, the one value of a uniform one, else a flag byte (0: not
// compressed) and the values.
std::size_t unpagedBytes(const vdbp::AttributeArray& array) {
  if (array.isTransient()) return 0;
  if (array.isUniform()) return array.storageTypeSize();
  return 1 + std::size_t{array.dataSize()} * array.storageTypeSize();
}

// A stream buffer over a stretch of memory of a fixed size: a write past its end fails.
class SpanSink final : public std::streambuf {
 public:
  SpanSink(char* data, std::size_t size) { setp(data, data + size); }
  bool full() const { return pptr() == epptr(); }
};

// Writes attribute `a` of leaves [begin, end) without blosc, each array by its writeBuffers()
// (PointDataLeafNode::writeBuffers() in pass a+3+k: writePagedBuffers() falls back to it), into
// the `size` bytes at `to`, which unpagedBytes() said they take.
void writeArrays(const std::vector<const Leaf*>& leaves, std::size_t begin, std::size_t end,
                 std::size_t a, const openvdb::io::StreamMetadata& metadata, char* to,
                 std::size_t size) {
  SpanSink sink(to, size);
  LeafStream stream(&sink, metadata);
  for (std::size_t l = begin; l < end; ++l)
    leaves[l]->attributeSet().getConst(a)->writeBuffers(stream.out(), /*outputTransient=*/false);
  if (!stream.out() || !sink.full())
    throw std::logic_error("VDB points: an attribute array took other than the bytes foreseen");
}

// One page of a paged attribute: the arrays' bytes it gathers, in order, and its two records,
// the size (in the sizes' pass) and the bytes (in the values' pass).
struct Page {
  std::vector<Piece> arrays;
  std::size_t bytes = 0;
  std::unique_ptr<MemorySink> values;
  char size[2 * sizeof(int)] = {};
  std::size_t sizeBytes = 0;
};

// Attribute `a`'s pages, as PagedOutputStream::write() cuts them: an array that would take the
// page past compression::PageSize closes it first; an array larger than a page is a page alone.
// Transient arrays are not written (writePagedBuffers()).
void cutPages(const std::vector<const Leaf*>& leaves, std::size_t a, std::vector<Page>& pages) {
  const auto pageSize = static_cast<std::size_t>(openvdb::compression::PageSize);
  Page page;
  auto close = [&] {
    if (page.bytes > 0) pages.push_back(std::move(page));
    page = Page();
  };
  for (const Leaf* leaf : leaves) {
    const vdbp::AttributeArray& array = *leaf->attributeSet().getConst(a);
    if (array.isTransient()) continue;
    const std::size_t bytes =
        std::size_t{array.isUniform() ? 1 : array.dataSize()} * array.storageTypeSize();
    if (bytes == 0) continue;
    const Piece piece{array.constDataAsByteArray(), bytes};
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
void encodePage(Page& page) {
  page.values = std::make_unique<MemorySink>(page.bytes);
  std::ostream out(page.values.get());
  openvdb::compression::PagedOutputStream stream(out);
  stream.setSizeOnly(false);
  for (const Piece& array : page.arrays)
    stream.write(array.data, static_cast<std::streamsize>(array.size));
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

// Whether the leaves can be encoded apart: every leaf with the same descriptor (so one is
// written, and every leaf has as many passes), every array in memory and whole (the serial writer
// would load or refuse it; here its bytes are read directly).
bool splittable(const std::vector<const Leaf*>& leaves) {
  const vdbp::AttributeSet::Descriptor& descriptor = leaves.front()->attributeSet().descriptor();
  for (const Leaf* leaf : leaves) {
    const vdbp::AttributeSet& set = leaf->attributeSet();
    if (&set.descriptor() != &descriptor && set.descriptor() != descriptor) return false;
    if (set.size() != descriptor.size()) return false;
    for (std::size_t a = 0; a < set.size(); ++a) {
      const vdbp::AttributeArray* array = set.getConst(a);
      if (array == nullptr || !array->isDataLoaded() ||
          (array->flags() & vdbp::AttributeArray::PARTIALREAD))
        return false;
    }
  }
  return true;
}

// A stretch of the file: bytes made already (`data`), or when `data` is null the unpaged arrays
// of attribute `attribute` of leaves [begin, end), `size` bytes, to be written into place.
struct Part {
  const char* data = nullptr;
  std::size_t size = 0;
  std::size_t attribute = 0, begin = 0, end = 0;
};

// Writes what Grid<PointDataTree>::writeBuffers(os) writes for `tree`, encoded in parallel, and
// returns true; or writes nothing and returns false when the tree is not splittable() (or has no
// leaf: two bytes that OpenVDB writes as fast) or `os` does not write into a MemorySink.
bool writeBuffersInParallel(const vdbp::PointDataTree& tree, bool toHalf, std::ostream& os) {
  auto* const sink = dynamic_cast<MemorySink*>(os.rdbuf());
  if (sink == nullptr) return false;
  std::vector<const Leaf*> leaves;
  leaves.reserve(tree.leafCount());
  for (auto leaf = tree.cbeginLeaf(); leaf; ++leaf) leaves.push_back(leaf.getLeaf());
  if (leaves.empty() || !splittable(leaves)) return false;
  const openvdb::io::StreamMetadata::Ptr metadata = openvdb::io::getStreamMetadataPtr(os);
  if (!metadata) throw std::runtime_error("VDB points: a stream without OpenVDB's metadata");

  const std::size_t attributes = leaves.front()->attributeSet().size();
  const bool paged = (openvdb::io::getDataCompression(os) & openvdb::io::COMPRESS_BLOSC) != 0;
  const std::vector<std::size_t> starts = leafRanges(leaves);
  const std::size_t ranges = starts.size() - 1;
  std::vector<RangeBytes> rangeBytes(ranges);
  std::vector<std::vector<Page>> pages(paged ? attributes : 0);
  for (std::size_t a = 0; a < pages.size(); ++a) cutPages(leaves, a, pages[a]);
  std::vector<Page*> allPages;
  for (std::vector<Page>& attributePages : pages)
    for (Page& page : attributePages) allPages.push_back(&page);

  // Leaf ranges then pages, one task each, one loop so that neither waits for the other.
  par::parallel_for(tbb::blocked_range<std::size_t>(0, ranges + allPages.size(), 1),
                    [&](const tbb::blocked_range<std::size_t>& tasks) {
                      for (std::size_t t = tasks.begin(); t < tasks.end(); ++t) {
                        if (t < ranges) {
                          encodeLeafRange(leaves, starts[t], starts[t + 1], *metadata, toHalf,
                                          rangeBytes[t]);
                        } else {
                          encodePage(*allPages[t - ranges]);
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
        for (std::size_t l = part.begin; l < part.end; ++l)
          part.size += unpagedBytes(*leaves[l]->attributeSet().getConst(a));
        parts.push_back(part);
      }
    }
  }

  const auto passes = static_cast<std::uint16_t>(leaves.front()->buffers());
  os.write(reinterpret_cast<const char*>(&passes), sizeof passes);
  // Each part's place, summed in advance, then every part written there at once.
  std::vector<std::size_t> offsets(parts.size() + 1, 0);
  for (std::size_t p = 0; p < parts.size(); ++p) offsets[p + 1] = offsets[p] + parts[p].size;
  char* const to = sink->append(offsets.back());
  par::parallel_for(tbb::blocked_range<std::size_t>(0, parts.size(), 1),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t p = r.begin(); p < r.end(); ++p) {
                        const Part& part = parts[p];
                        if (part.size == 0) continue;
                        if (part.data != nullptr) {
                          std::memcpy(to + offsets[p], part.data, part.size);
                        } else {
                          writeArrays(leaves, part.begin, part.end, part.attribute, *metadata,
                                      to + offsets[p], part.size);
                        }
                      }
                    });
  return true;
}

// The grid as Archive::write() sees it: the same tree, metadata and transform (a shallow copy),
// its leaves' buffers written by writeBuffersInParallel(). Archive::write() calls the virtual
// GridBase::writeBuffers() between the topology and the grid's end offset, which it then patches
// into the grid's descriptor itself.
class ParallelBuffersGrid final : public vdbp::PointDataGrid {
 public:
  explicit ParallelBuffersGrid(vdbp::PointDataGrid& grid)
      : vdbp::PointDataGrid(grid, openvdb::ShallowCopy()) {}
  void writeBuffers(std::ostream& os) const override {
    if (!writeBuffersInParallel(constTree(), saveFloatAsHalf(), os))
      vdbp::PointDataGrid::writeBuffers(os);
  }
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

FileBytes encodePointsFile(vdbp::PointDataGrid& grid, std::uint32_t compression,
                           std::size_t expectedBytes) {
  const openvdb::GridCPtrVec grids{std::make_shared<const ParallelBuffersGrid>(grid)};
  MemorySink sink(expectedBytes);
  std::ostream os(&sink);
  PointsArchive(compression).writeSeekable(os, grids);
  if (!os) throw std::runtime_error("cannot encode the VDB points grid");
  return std::move(sink).release();
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
