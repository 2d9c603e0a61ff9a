// A .vdb file of one PointDataGrid made in memory, its leaves' buffers encoded on every thread.
// Internal to io/ (not installed): it includes OpenVDB's headers, which VdbPointCache.h keeps out.
#pragma once

#include <openvdb/points/PointDataGrid.h>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

namespace tickfx::io {

/// Bytes made in memory, in storage left uninitialised until they are written: the threads that
/// fill its parts fault its pages in, where a std::string would be zeroed first, on one thread.
/// Large storage (2 MiB or more) asks Linux for transparent huge pages (madvise), so that filling
/// it takes a page fault every 2 MiB rather than every 4 KiB, and is kept when freed, for the
/// next frame's buffers of about its size (up to 2 GiB of it, the least recently freed given
/// back first): in a virtual machine faulting pages in and handing them back cost more than the
/// copying itself.
class FileBytes {
 public:
  struct Free {
    void operator()(void* p) const;
  };
  using Storage = std::unique_ptr<char[], Free>;

  /// Uninitialised storage for `size` bytes (std::bad_alloc when there is none).
  static Storage allocate(std::size_t size);

  FileBytes() = default;
  FileBytes(Storage data, std::size_t size) : data_(std::move(data)), size_(size) {}
  char* data() { return data_.get(); }
  const char* data() const { return data_.get(); }
  std::size_t size() const { return size_; }

 private:
  Storage data_;
  std::size_t size_ = 0;
};

/// The values of a grid's attribute arrays, given by the caller instead of held by the arrays: a
/// grid of a million points need not copy them into its leaves to be written.
class PointValues {
 public:
  virtual ~PointValues() = default;
  /// Writes attribute `attribute`'s values of the `count` points of the leaf at `origin` into
  /// `to`, as the leaf's array would store them (its codec's StorageType each, no stride), in the
  /// order of the leaf's array. Called from several threads at once, for different leaves or
  /// attributes.
  virtual void store(std::size_t attribute, const openvdb::Coord& origin, std::size_t count,
                     char* to) const = 0;
};

/// Uninitialised storage for `n` values of T (a type a plain copy creates, as numbers and
/// openvdb::Vec3f are), allocated as FileBytes::allocate() allocates: its pages are faulted in by
/// the threads that first write them, 2 MiB at a time where it is large.
template <typename T>
using LargeArray = std::unique_ptr<T[], FileBytes::Free>;

template <typename T>
LargeArray<T> allocateLargeArray(std::size_t n) {
  static_assert(std::is_trivially_copyable_v<T> && std::is_trivially_destructible_v<T>);
  return LargeArray<T>(reinterpret_cast<T*>(FileBytes::allocate(n * sizeof(T)).release()));
}

/// A points grid's leaves as encodePointsFile() writes them, in place of a tree of
/// PointDataLeafNodes (whose making, adding and freeing took some 4 ms of a thread at 10⁶
/// points, for a tree written once): what each leaf would hold but its arrays, whose values a
/// PointValues stores.
struct PointLeaves {
  using Leaf = openvdb::points::PointDataTree::LeafNodeType;
  /// Each leaf's origin (each axis a multiple of Leaf::DIM), each once, in ascending Coord order.
  std::vector<openvdb::Coord> origins;
  /// Each leaf's point count, at least 1.
  std::vector<std::size_t> counts;
  /// Each leaf's active voxels: those that hold points.
  std::vector<Leaf::NodeMaskType> masks;
  /// Each leaf's Leaf::SIZE voxel values, leaf after leaf: the end of each voxel's points in the
  /// leaf's arrays (PointDataLeafNode's offsets).
  LargeArray<openvdb::PointDataIndex32> voxelEnds;
  /// A leaf whose attribute set is every leaf's: one point, each array uniform and of stride 1.
  /// Each leaf's arrays are these expanded to its point count.
  std::unique_ptr<Leaf> sample;

  std::size_t size() const { return origins.size(); }
};

/// A .vdb file encoded in memory but for its largest part, the attribute arrays' values without
/// blosc: those are stored as the file is written, a chunk at a time on every thread, while the
/// chunk made before goes to the kernel; the rest of the leaves' buffers (voxel offsets, the
/// arrays' records, blosc's pages), made beforehand, are copied into the same chunks. The file
/// is then never whole in memory, its values go through the cache on their way to the page
/// cache, and storing them overlaps writing them. Holds what it was made from (the grid's leaves
/// and the caller's PointValues), which must outlive it.
class EncodedPointsFile {
 public:
  /// The bytes not yet made, filled on demand.
  class Deferred {
   public:
    virtual ~Deferred() = default;
    virtual std::size_t size() const = 0;
    /// Writes bytes [from, to) of them at `out`. Called from several threads at once, for
    /// ranges that do not overlap.
    virtual void fill(std::size_t from, std::size_t to, char* out) const = 0;
  };

  /// `known`: the file's bytes but the deferred ones, which go at `deferredAt`.
  EncodedPointsFile(FileBytes known, std::size_t deferredAt, std::unique_ptr<Deferred> deferred);
  EncodedPointsFile(EncodedPointsFile&&) noexcept = default;
  ~EncodedPointsFile();

  /// The bytes before the deferred ones (the header first), for the caller to change in place.
  char* head() { return known_.data(); }
  std::size_t headSize() const { return at_; }
  std::size_t size() const;
  /// Writes the whole file to `out`, in order, in blocks that start at multiples of 512 KiB from
  /// the file's first byte (a page cache of large folios takes a write into a new file a fifth
  /// faster when its offset is so aligned: `out` should be at the start of its file); stops at
  /// the first failed write (`out` tells). The calling thread writes; the arena's other threads
  /// make the blocks ahead of it.
  void write(std::ostream& out) const;
  /// The whole file in memory.
  FileBytes bytes() const;

 private:
  // Writes bytes [from, to) of the file at `out`.
  void fill(std::size_t from, std::size_t to, char* out) const;

  FileBytes known_;
  std::size_t at_ = 0;
  std::unique_ptr<Deferred> deferred_;
};

/// What openvdb::io::File::write() writes for a PointDataGrid alone (its name unique, no file
/// metadata) with `compression` (openvdb::io::COMPRESS_* flags), to be made as it is written: the
/// bytes of io::Archive::write(os, {grid}, seekable = true), every one of them but the header's
/// UUID, which OpenVDB draws at random each time. (File writes through its own std::ofstream and
/// ignores its failures, so a full disk left a truncated .vdb under the frame's name and the run
/// went on: writeVdbPointCache writes these bytes with writeFileAtomically instead.)
/// The grid is `grid`, which holds no leaf (its name, metadata and transform), with the leaves
/// `leaves`, each holding the sample's attributes expanded to its point count, with the values
/// `values` stores. OpenVDB writes the header, the grid's descriptor (and the offsets it patches
/// in), its metadata and transform into memory, as ever; the topology, the file's statistics
/// and the leaves' buffers (voxel offsets, the arrays' records, blosc's pages) are made here, by
/// OpenVDB's own calls for each node, leaf, array and page, on every thread (TBB), leaf range by
/// leaf range and page by page, begun while the header is written; the arrays' values without
/// blosc, nearly all of the file, are stored as the file is written (EncodedPointsFile). The
/// bytes do not depend on the thread count. Without leaves, OpenVDB writes the grid alone, to
/// the same bytes. A sample whose arrays are not uniform, of one point and stride 1 throws
/// std::logic_error. `expectedBytes`: the room reserved for the header, metadata and topology.
/// `grid`, `leaves` and `values` must outlive the result.
EncodedPointsFile encodePointsFile(const openvdb::points::PointDataGrid& grid,
                                   const PointLeaves& leaves, std::uint32_t compression,
                                   const PointValues& values, std::size_t expectedBytes = 1 << 20);

/// The same bytes made by io::Archive::write() alone, on one thread, into a std::ostringstream:
/// the way tickfx wrote its caches before encodePointsFile, kept as the tests' reference.
/// `expectedBytes`: the room reserved for the whole file.
std::string encodePointsFileSerially(const openvdb::points::PointDataGrid::ConstPtr& grid,
                                     std::uint32_t compression, std::size_t expectedBytes);

}  // namespace tickfx::io
