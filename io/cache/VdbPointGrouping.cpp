#include "io/cache/VdbPointGrouping.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <tbb/parallel_sort.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cstdint>
#include <cstring>
#include <limits>
#include <optional>
#include <utility>
#include <vector>

#include "io/cache/VdbPointPlacement.h"
#include "io/util/ProfiledTbb.h"

namespace tickfx::io {
namespace {

namespace vdbp = openvdb::points;
using Leaf = vdbp::PointDataTree::LeafNodeType;

constexpr std::size_t kPlacementGrain = 16384;

// Where a point goes: its leaf, its voxel in the leaf, and its row (which orders the points of a
// voxel, so the order is total and a parallel sort gives one answer).
struct PointSlot {
  openvdb::Coord leaf;
  openvdb::Index32 voxel = 0;
  std::size_t row = 0;
  bool operator<(const PointSlot& o) const {
    if (leaf != o.leaf) return leaf < o.leaf;
    if (voxel != o.voxel) return voxel < o.voxel;
    return row < o.row;
  }
};

// Each point's leaf and voxel offset within its leaf (0 to 511), in row order (sorted below).
template <bool Quantised>
std::vector<PointSlot> slotsInRowOrder(const FrameData& frame) {
  const std::size_t n = frame.size();
  const Positions positions(frame);
  std::vector<PointSlot> slots(n);
  par::parallel_for(tbb::blocked_range<std::size_t>(0, n, kPlacementGrain),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t i = range.begin(); i < range.end(); ++i) {
                        const openvdb::Coord voxel = positions.voxel<Quantised>(i);
                        slots[i] =
                            PointSlot{voxel & kLeafMask,
                                      static_cast<openvdb::Index32>(Leaf::coordToOffset(voxel)), i};
                      }
                    });
  return slots;
}

// The slots in (leaf, voxel, row) order by a sort of 64-bit keys, when the leaves' bounding box,
// 512 voxels and the rows fit in 64 bits (any effect of sane size): the leaf's index in the box
// (x, then y, then z, as Coord's order), its voxel and its row, one integer a point, so a plain
// integer sort gives exactly the order of PointSlot::operator<. False, slots untouched, otherwise.
bool sortByKeys(std::vector<PointSlot>& slots) {
  const std::size_t n = slots.size();
  if (n == 0) return true;
  using Box = std::pair<openvdb::Coord, openvdb::Coord>;
  const auto leafBox = par::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, n, kPlacementGrain),
      Box{openvdb::Coord::max(), openvdb::Coord::min()},
      [&](const tbb::blocked_range<std::size_t>& range, Box box) {
        for (std::size_t i = range.begin(); i < range.end(); ++i) {
          box.first.minComponent(slots[i].leaf);
          box.second.maxComponent(slots[i].leaf);
        }
        return box;
      },
      [](Box a, const Box& b) {  // min and max: the same answer in any grouping
        a.first.minComponent(b.first);
        a.second.maxComponent(b.second);
        return a;
      });
  constexpr int kLeafLog2 = static_cast<int>(Leaf::LOG2DIM);
  std::array<std::uint64_t, 3> extent{};
  for (int c = 0; c < 3; ++c) {
    extent[static_cast<std::size_t>(c)] =
        (static_cast<std::uint64_t>(static_cast<std::int64_t>(leafBox.second[c]) -
                                    leafBox.first[c]) >>
         kLeafLog2) +
        1;
  }
  const int rowBits = std::bit_width(n - 1);
  const int voxelBits = 3 * kLeafLog2;
  int leafBits = 0;
  for (const std::uint64_t e : extent) leafBits += std::bit_width(e);
  if (leafBits + voxelBits + rowBits > 64) return false;

  const auto leafIndex = [&](const openvdb::Coord& leaf) {
    std::uint64_t index = 0;
    for (int c = 0; c < 3; ++c) {
      index = index * extent[static_cast<std::size_t>(c)] +
              (static_cast<std::uint64_t>(static_cast<std::int64_t>(leaf[c]) - leafBox.first[c]) >>
               kLeafLog2);
    }
    return index;
  };
  std::vector<std::uint64_t> keys(n);
  par::parallel_for(tbb::blocked_range<std::size_t>(0, n, kPlacementGrain),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t i = range.begin(); i < range.end(); ++i) {
                        const PointSlot& s = slots[i];
                        keys[i] = (leafIndex(s.leaf) << (voxelBits + rowBits)) |
                                  (std::uint64_t{s.voxel} << rowBits) | s.row;
                      }
                    });
  par::parallel_sort(keys.begin(), keys.end());
  // Rebuilt from the keys, in their order: the row names the point, whose leaf and voxel are
  // those of its unsorted slot.
  std::vector<PointSlot> sorted(n);
  const std::uint64_t rowMask = (std::uint64_t{1} << rowBits) - 1;
  par::parallel_for(tbb::blocked_range<std::size_t>(0, n, kPlacementGrain),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t k = range.begin(); k < range.end(); ++k) {
                        sorted[k] = slots[static_cast<std::size_t>(keys[k] & rowMask)];
                      }
                    });
  slots = std::move(sorted);
  return true;
}

// Consecutive leaves gathered for the counting sort: at most kBucketLeaves leaves and, unless a
// leaf alone holds more, kBucketPoints points or a kBucketShare-th of the frame's, whichever is
// more. Rows are first scattered by bucket (some 550 streams at 10⁶ and 10⁷ points over a 100 m
// box, where a scatter by leaf wrote 2200 and missed the cache on nearly every value), each
// bucket's rows in row order; then each bucket is put in order by leaf and voxel, and the store
// gathers each leaf's values from its bucket's rows. A bucket's rows of a column should stay in
// the first caches while its leaves are gathered (2048 offsets take 24 KiB): buckets of up to 16
// leaves and a 128th of the frame (140 streams) made the frame 6 % slower at 10⁶ points and 21 %
// slower at 10⁷, where a bucket's offsets took 900 KiB (docs/performance.md).
constexpr std::size_t kBucketPoints = 2048;
constexpr std::size_t kBucketShare = 512;
constexpr std::uint32_t kBucketLeaves = 16;
constexpr unsigned kVoxelBits = 3 * Leaf::LOG2DIM;  // a voxel's index in its leaf
static_assert(std::size_t{1} << kVoxelBits == Leaf::SIZE);
static_assert((kBucketLeaves << kVoxelBits) - 1 <= std::numeric_limits<std::uint16_t>::max(),
              "a point's key in its bucket (leaf, voxel) fits the voxel column's 16 bits");

// A float column of GroupedPoints from the frame: `width` of the frame's columns a row.
struct SourceColumn {
  std::array<const float*, 3> lanes{};
  std::size_t width = 1;
};

// GroupedPoints::columns' sources, in its order.
std::vector<SourceColumn> pointFloatColumns(const FrameData& frame) {
  std::vector<SourceColumn> columns(kStandardFloatColumns);
  columns[kVelocityColumn] = {
      {frame.velocity[0].data(), frame.velocity[1].data(), frame.velocity[2].data()}, 3};
  columns[kAgeColumn] = {{frame.age.data()}, 1};
  columns[kLifeColumn] = {{frame.life.data()}, 1};
  columns[kMassColumn] = {{frame.mass.data()}, 1};
  for (const FloatColumn& a : frame.attributes) columns.push_back({{a.data()}, 1});
  return columns;
}

// Rows compared at a time by isUniform(): a column that differs shows it in its first block
// (at once, for any column of measured values), a uniform one is read whole.
constexpr std::size_t kUniformBlock = 4096;

// Whether the n values at x all hold the same bits: bits, not numbers (−0.0 is not 0.0, and
// each NaN's payload counts), so the answer is a pure function of the values.
bool isUniform(const float* x, std::size_t n) {
  const auto differs = [x](std::uint32_t first, std::size_t begin, std::size_t end) {
    std::uint32_t other = 0;  // (no exit within a block: the loop is vectorised)
    for (std::size_t i = begin; i < end; ++i) other |= std::bit_cast<std::uint32_t>(x[i]) ^ first;
    return other != 0;
  };
  if (n == 0) return false;
  const auto first = std::bit_cast<std::uint32_t>(x[0]);
  if (differs(first, 0, std::min(n, kUniformBlock))) return false;
  std::atomic<bool> found{false};
  par::parallel_for(tbb::blocked_range<std::size_t>(0, n, 16 * kUniformBlock),
                    [&](const tbb::blocked_range<std::size_t>& rows) {
                      for (std::size_t i = rows.begin(); i < rows.end(); i += kUniformBlock) {
                        if (found.load(std::memory_order_relaxed)) return;
                        if (differs(first, i, std::min(rows.end(), i + kUniformBlock)))
                          found.store(true, std::memory_order_relaxed);
                      }
                    });
  return !found.load();
}

// Gives `points` its float columns, one for each of the frame's (pointFloatColumns()), each a
// row as wide as its source but for a column of one float a row whose rows are all the same
// (isUniform()), which holds its one value (width 0). Returns the sources, in the same order:
// where the grouping copies each column's rows from, as wide as the column it fills says.
std::vector<SourceColumn> addFloatColumns(GroupedPoints& points, const FrameData& frame) {
  const std::size_t n = frame.size();
  std::vector<SourceColumn> source = pointFloatColumns(frame);
  for (const SourceColumn& c : source) {
    GroupedPoints::Column& column = points.columns.emplace_back();
    column.width = c.width == 1 && isUniform(c.lanes[0], n) ? 0 : c.width;
    column.values = allocateLargeArray<float>(std::max<std::size_t>(n * column.width, 1));
    if (column.width == 0) column.values[0] = c.lanes[0][0];
  }
  return source;
}

// Each leaf's point count, from the starts, and room for its voxel ends and mask.
void describeLeaves(GroupedPoints& points) {
  PointLeaves& leaves = points.leaves;
  for (std::size_t l = 0; l < leaves.origins.size(); ++l)
    leaves.counts.push_back(points.starts[l + 1] - points.starts[l]);
  leaves.voxelEnds = allocateLargeArray<openvdb::PointDataIndex32>(leaves.size() * Leaf::SIZE);
  leaves.masks.resize(leaves.size());
}

// Leaf l's voxel ends and mask from its voxels' point counts (Leaf::SIZE of them, at `counts`),
// the leaf's points beginning at `first` in some run of points: what setOffsets(ends,
// /*updateValueMask=*/true) sets on a leaf, without its two calls a voxel. Each count is replaced
// by its voxel's first place in the run (a counting sort's starts).
// (Four voxels at a time in SSE2's registers, the baseline's: each one's end the sum of the
// counts up to it, by two shifted adds and the voxels' before; a loop voxel by voxel waited on
// each sum, and took half of the buckets' sort.)
void setVoxelEnds(GroupedPoints& points, std::size_t l, std::uint32_t* counts,
                  std::uint32_t first) {
  using Lanes = std::uint32_t __attribute__((vector_size(16)));
  constexpr std::size_t kLanes = sizeof(Lanes) / sizeof(std::uint32_t);
  openvdb::PointDataIndex32* const ends = points.leaves.voxelEnds.get() + l * Leaf::SIZE;
  static_assert(sizeof(openvdb::PointDataIndex32) == sizeof(std::uint32_t));
  Leaf::NodeMaskType& mask = points.leaves.masks[l];
  const Lanes zero{}, laneBit{1, 2, 4, 8};
  Lanes before{};  // each lane: the points of the voxels before these four
  std::uint64_t word = 0;
  for (std::size_t v = 0; v < Leaf::SIZE; v += kLanes) {
    Lanes n;
    std::memcpy(&n, counts + v, sizeof n);
    Lanes sum = n + __builtin_shufflevector(zero, n, 0, 4, 5, 6);  // lane i: n[i − 1] + n[i]
    sum += __builtin_shufflevector(zero, sum, 0, 0, 4, 5);         // lane i: n[0] + … + n[i]
    const Lanes end = before + sum;
    const Lanes start = end - n + first;
    std::memcpy(static_cast<void*>(ends + v), &end, sizeof end);
    std::memcpy(counts + v, &start, sizeof start);
    before = __builtin_shufflevector(end, end, 3, 3, 3, 3);
    // The four voxels' bits of the mask, those that hold points (lanes' bits summed).
    Lanes bits = laneBit & reinterpret_cast<Lanes>(n != zero);
    bits += __builtin_shufflevector(bits, bits, 2, 3, 0, 1);
    bits += __builtin_shufflevector(bits, bits, 1, 0, 3, 2);
    word |= std::uint64_t{bits[0]} << (v % 64);
    if (v % 64 == 64 - kLanes) {
      mask.template getWord<std::uint64_t>(v / 64) = word;
      word = 0;
    }
  }
}

// The general way: every point's slot, sorted by (leaf, voxel, row).
template <bool Quantised>
GroupedPoints sortedPoints(const FrameData& frame) {
  std::vector<PointSlot> slots = slotsInRowOrder<Quantised>(frame);
  if (!sortByKeys(slots)) par::parallel_sort(slots.begin(), slots.end());
  GroupedPoints points(slots.size());
  const std::vector<SourceColumn> source = addFloatColumns(points, frame);
  const Positions positions(frame);
  par::parallel_for(tbb::blocked_range<std::size_t>(0, slots.size(), kPlacementGrain),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t k = range.begin(); k < range.end(); ++k) {
                        const std::size_t r = slots[k].row;
                        positions.voxel<Quantised>(r, &points.offset[k]);
                        points.id[k] = frame.id[r];
                        for (std::size_t j = 0; j < source.size(); ++j) {
                          const std::size_t width = points.columns[j].width;  // (0: none)
                          for (std::size_t lane = 0; lane < width; ++lane)
                            points.columns[j].values[k * width + lane] = source[j].lanes[lane][r];
                        }
                      }
                    });
  for (std::size_t k = 0; k < slots.size(); ++k) {
    if (k == 0 || slots[k].leaf != slots[k - 1].leaf) {
      points.starts.push_back(k);
      points.leaves.origins.push_back(slots[k].leaf);
    }
  }
  points.starts.push_back(slots.size());
  describeLeaves(points);
  par::parallel_for(tbb::blocked_range<std::size_t>(0, points.leaves.size()),
                    [&](const tbb::blocked_range<std::size_t>& leaves) {
                      for (std::size_t l = leaves.begin(); l < leaves.end(); ++l) {
                        std::array<std::uint32_t, Leaf::SIZE> counts{};
                        for (std::size_t k = points.starts[l]; k < points.starts[l + 1]; ++k)
                          ++counts[slots[k].voxel];
                        setVoxelEnds(points, l, counts.data(), 0);
                      }
                    });
  return points;
}

// Asks for the cache line after the one that holds *p, to be written. The scatter by bucket
// writes some 140 streams at once, too many for the processor's prefetchers to follow, so each
// line's first store would wait for the line to be read (a stream's next line is needed only
// after its current one fills, a hundred rows or more later). A hint: it touches no memory, and
// the line may lie past the array's end (the address is made as an integer).
template <typename T>
inline void prefetchNextLine(const T* p) {
  constexpr std::uintptr_t kLine = 64;
  __builtin_prefetch(reinterpret_cast<const void*>(reinterpret_cast<std::uintptr_t>(p) + kLine),
                     /*write=*/1, /*locality=*/3);
}

// to[at[i]] = from[i] for rows [begin, end).
template <typename T>
void scatter(const T* __restrict from, const std::uint32_t* __restrict at, std::size_t begin,
             std::size_t end, T* __restrict to) {
  for (std::size_t i = begin; i < end; ++i) {
    prefetchNextLine(to + at[i]);
    to[at[i]] = from[i];
  }
}

// to[3 at[i] + c] = from[c][i] for rows [begin, end): three columns into rows of three, one
// stream a bucket rather than three.
void scatterRows(const std::array<const float*, 3>& from, const std::uint32_t* __restrict at,
                 std::size_t begin, std::size_t end, float* __restrict to) {
  const float* __restrict x = from[0], * __restrict y = from[1], * __restrict z = from[2];
  for (std::size_t i = begin; i < end; ++i) {
    float* const row = to + std::size_t{3} * at[i];
    prefetchNextLine(row);
    row[0] = x[i];
    row[1] = y[i];
    row[2] = z[i];
  }
}

// Rows are bucketed in chunks of about this many, at most kMaxChunks chunks.
constexpr std::size_t kBucketChunk = 65536;
constexpr std::size_t kMaxChunks = 64;

// Puts bucket b's points, in row order, in order by their keys (`keys`, each its leaf's place in
// the bucket, then its voxel), rows in order among equal keys (a counting sort): each point's row
// is kept in `source`, through which the store gathers its values. Each leaf's voxel ends and
// mask are set as its counts are summed (one pass over the voxels, which outnumber the points).
void orderBucket(GroupedPoints& points, const std::uint16_t* keys, std::size_t b,
                 std::vector<std::uint32_t>& counts) {
  const auto [begin, end] = points.bucketPoints(b);
  const std::size_t count = end - begin;
  const std::uint32_t firstLeaf = points.buckets.first[b], endLeaf = points.buckets.first[b + 1];
  const std::uint16_t* const key = keys + begin;
  counts.assign(std::size_t{endLeaf - firstLeaf} << kVoxelBits, 0);
  for (std::size_t i = 0; i < count; ++i) ++counts[key[i]];
  // Each key's count becomes its first place (a leaf's points begin at its start).
  for (std::uint32_t l = firstLeaf; l < endLeaf; ++l) {
    setVoxelEnds(points, l, counts.data() + (std::size_t{l - firstLeaf} << kVoxelBits),
                 static_cast<std::uint32_t>(points.starts[l]));
  }
  std::uint32_t* const source = points.source.get();
  for (std::size_t i = 0; i < count; ++i)
    source[counts[key[i]]++] = static_cast<std::uint32_t>(begin + i);
}

// The fast way, when the leaves' bounding box holds few enough leaves to count them in a table
// (any effect of sane size): a stable counting sort of the rows by the leaf's index in the box
// (x, then y, then z: Coord's order), in two steps: by bucket of leaves, then within each bucket
// by leaf and voxel (Buckets, orderBucket). The chunks of rows are fixed by the point count and
// the thread count; the order depends on neither. Nothing otherwise.
template <bool Quantised>
std::optional<GroupedPoints> bucketedPoints(const FrameData& frame) {
  const std::size_t n = frame.size();
  if (n == 0 || n > std::numeric_limits<std::uint32_t>::max()) return std::nullopt;
  // A box holding every point's leaf (a larger one would give the same order): the voxel of a
  // finite coordinate within the bound rises with it, and any other is in voxel 0.
  struct Range {
    std::array<float, 3> low{}, high{};
    bool placedAtZero = false;
  };
  Range init;
  init.low.fill(std::numeric_limits<float>::infinity());
  init.high.fill(-std::numeric_limits<float>::infinity());
  const RowKernels<Quantised> kernels;
  const Range range = par::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, n, kPlacementGrain), init,
      [&](const tbb::blocked_range<std::size_t>& rows, Range r) {
        for (std::size_t c = 0; c < 3; ++c) {
          r.placedAtZero |= kernels.bounds(frame.position[static_cast<int>(c)].data(), rows.begin(),
                                           rows.end(), r.low[c], r.high[c]);
        }
        return r;
      },
      [](Range a, const Range& b) {  // min, max and or: the same answer in any grouping
        for (std::size_t c = 0; c < 3; ++c) {
          a.low[c] = std::min(a.low[c], b.low[c]);
          a.high[c] = std::max(a.high[c], b.high[c]);
        }
        a.placedAtZero |= b.placedAtZero;
        return a;
      });
  std::pair<openvdb::Coord, openvdb::Coord> box{openvdb::Coord::max(), openvdb::Coord::min()};
  for (int c = 0; c < 3; ++c) {
    const auto k = static_cast<std::size_t>(c);
    if (range.low[k] <= range.high[k]) {
      box.first[c] = std::min(box.first[c], nearestVoxel(range.low[k]).first & kLeafMask);
      box.second[c] = std::max(box.second[c], nearestVoxel(range.high[k]).first & kLeafMask);
    }
    if (range.placedAtZero) {
      box.first[c] = std::min(box.first[c], 0);
      box.second[c] = std::max(box.second[c], 0);
    }
  }
  // A multiple of the threads, so that each takes as many (the order does not depend on them): at
  // 10⁶ points 16 chunks rather than 15 on 2 threads took 0.4–1.0 ms off the grouping's 12.
  std::size_t chunks = std::clamp<std::size_t>(n / kBucketChunk, 1, kMaxChunks);
  if (const auto threads = static_cast<std::size_t>(tbb::this_task_arena::max_concurrency());
      threads <= kMaxChunks) {
    chunks = std::min(kMaxChunks / threads, (chunks + threads - 1) / threads) * threads;
  }
  // Table entries, leaves × chunks (leaf indices and the table's offsets fit 32 bits).
  const std::uint64_t limit = std::min<std::uint64_t>(8 * std::uint64_t{n} + (1u << 20),
                                                      std::numeric_limits<std::uint32_t>::max());
  constexpr int kLeafLog2 = static_cast<int>(Leaf::LOG2DIM);
  std::array<std::uint64_t, 3> extent{};
  std::uint64_t leafCount = 1;
  for (int c = 0; c < 3; ++c) {
    const std::uint64_t e =
        (static_cast<std::uint64_t>(static_cast<std::int64_t>(box.second[c]) - box.first[c]) >>
         kLeafLog2) +
        1;
    extent[static_cast<std::size_t>(c)] = e;
    if (e > limit / (leafCount * chunks)) return std::nullopt;  // (no product overflows)
    leafCount *= e;
  }
  const std::size_t leaves = leafCount;
  LeafBox leafBox;
  for (std::size_t c = 0; c < 3; ++c) {
    leafBox.first[c] = box.first[static_cast<int>(c)];
    leafBox.last[c] = box.second[static_cast<int>(c)];
    leafBox.extent[c] = static_cast<std::uint32_t>(extent[c]);
  }
  const auto chunkRange = [&](std::size_t chunk) {
    return std::pair{chunk * n / chunks, (chunk + 1) * n / chunks};
  };
  // Each row's leaf, and each chunk's count of rows a leaf.
  const Positions positions(frame);
  const LargeArray<std::uint32_t> rowAt = allocateLargeArray<std::uint32_t>(n);
  std::vector<std::uint32_t> table(leaves * chunks, 0);
  std::vector<char> outsideBox(chunks, 0);
  par::parallel_for(std::size_t{0}, chunks, [&](std::size_t chunk) {
    std::uint32_t* count = table.data() + chunk * leaves;
    const auto [begin, end] = chunkRange(chunk);
    PlacedRows placed;
    for (std::size_t first = begin; first < end; first += kPlacedRows) {
      const std::size_t rows = std::min(kPlacedRows, end - first);
      kernels.place(positions, first, rows, placed);
      std::uint32_t* const leaf = rowAt.get() + first;
      // (Never outside, as the box is made; but a wrong box must not write past the table.)
      if (!kernels.index(placed, rows, leafBox, leaf)) {
        outsideBox[chunk] = 1;
        return;
      }
      for (std::size_t k = 0; k < rows; ++k) ++count[leaf[k]];
    }
  });
  if (std::find(outsideBox.begin(), outsideBox.end(), 1) != outsideBox.end()) return std::nullopt;
  GroupedPoints points(n);
  const std::vector<SourceColumn> source = addFloatColumns(points, frame);
  // Each row's key in its bucket, at its place there: its leaf's place in the bucket, its voxel.
  const LargeArray<std::uint16_t> keys = allocateLargeArray<std::uint16_t>(n);
  // The leaves that hold points, in order (each one's first point and origin), and the buckets.
  std::vector<std::uint32_t> boxOf;  // each such leaf's index in the box
  std::size_t sum = 0;
  for (std::size_t l = 0; l < leaves; ++l) {
    std::size_t total = 0;
    for (std::size_t chunk = 0; chunk < chunks; ++chunk) total += table[chunk * leaves + l];
    if (total == 0) continue;
    boxOf.push_back(static_cast<std::uint32_t>(l));
    points.starts.push_back(sum);
    sum += total;
    const std::uint64_t z = l % extent[2], y = (l / extent[2]) % extent[1],
                        x = l / (extent[2] * extent[1]);
    points.leaves.origins.push_back(box.first +
                                    openvdb::Coord(static_cast<openvdb::Int32>(x << kLeafLog2),
                                                   static_cast<openvdb::Int32>(y << kLeafLog2),
                                                   static_cast<openvdb::Int32>(z << kLeafLog2)));
  }
  points.starts.push_back(n);
  Buckets buckets(points.starts);
  // Each box leaf's bucket and place in it (bucket << 4 | place), looked up once a row.
  static_assert(kBucketLeaves <= 16);
  std::vector<std::uint32_t> bucketPlace(leaves);
  for (std::size_t o = 0; o < boxOf.size(); ++o) {
    const std::uint32_t b = buckets.of[o];
    bucketPlace[boxOf[o]] = b << 4 | (static_cast<std::uint32_t>(o) - buckets.first[b]);
  }
  // Where each chunk's rows of a bucket go: bucket by bucket, chunk by chunk.
  const std::size_t bucketCount = buckets.count();
  std::vector<std::uint32_t> next(chunks * bucketCount);
  for (std::size_t b = 0; b < bucketCount; ++b) {
    auto at = static_cast<std::uint32_t>(points.starts[buckets.first[b]]);
    for (std::size_t chunk = 0; chunk < chunks; ++chunk) {
      next[chunk * bucketCount + b] = at;
      for (std::uint32_t o = buckets.first[b]; o < buckets.first[b + 1]; ++o)
        at += table[chunk * leaves + boxOf[o]];
    }
  }
  // Each row's place in its bucket (rows in order within a bucket) and its key there, the place
  // of its leaf in the bucket and its voxel, then its values, one column at a time over a run of
  // chunks: a column's writes go to one line a bucket at a time, which stay in cache from one
  // chunk to the next (all the columns of a chunk at once would evict each other's lines).
  par::parallel_for(
      tbb::blocked_range<std::size_t>(0, chunks, 1),
      [&](const tbb::blocked_range<std::size_t>& run) {
        std::uint32_t* const at = rowAt.get();
        std::uint16_t* const __restrict key = keys.get();
        openvdb::Vec3f* const __restrict offset = points.offset.get();
        PlacedRows placed;
        for (std::size_t chunk = run.begin(); chunk < run.end(); ++chunk) {
          std::uint32_t* const chunkNext = next.data() + chunk * bucketCount;
          const auto [begin, end] = chunkRange(chunk);
          for (std::size_t first = begin; first < end; first += kPlacedRows) {
            const std::size_t rows = std::min(kPlacedRows, end - first);
            kernels.place(positions, first, rows, placed);
            for (std::size_t k = 0; k < rows; ++k) {
              const std::uint32_t p = bucketPlace[at[first + k]];
              const std::uint32_t to = chunkNext[p >> 4]++;
              at[first + k] = to;
              prefetchNextLine(key + to);
              prefetchNextLine(offset + to);
              key[to] = static_cast<std::uint16_t>(
                  ((p & 15) << kVoxelBits) |
                  static_cast<std::uint32_t>(Leaf::coordToOffset(placed.voxel(k))));
              offset[to] =
                  openvdb::Vec3f(placed.offset[0][k], placed.offset[1][k], placed.offset[2][k]);
            }
          }
        }
        const std::size_t runBegin = chunkRange(run.begin()).first;
        const std::size_t runEnd = chunkRange(run.end() - 1).second;
        scatter(frame.id.data(), at, runBegin, runEnd, points.id.get());
        for (std::size_t j = 0; j < source.size(); ++j) {
          const std::size_t width = points.columns[j].width;  // (0: its one value, set once)
          if (width == 3)
            scatterRows(source[j].lanes, at, runBegin, runEnd, points.columns[j].values.get());
          else if (width == 1)
            scatter(source[j].lanes[0], at, runBegin, runEnd, points.columns[j].values.get());
        }
      });
  // Each bucket (in cache) in order by key: by leaf, then voxel, rows in order within a voxel.
  points.source = allocateLargeArray<std::uint32_t>(n);
  points.buckets = std::move(buckets);
  describeLeaves(points);
  par::parallel_for(tbb::blocked_range<std::size_t>(0, bucketCount),
                    [&](const tbb::blocked_range<std::size_t>& some) {
                      std::vector<std::uint32_t> counts;
                      for (std::size_t b = some.begin(); b < some.end(); ++b)
                        orderBucket(points, keys.get(), b, counts);
                    });
  return points;
}

}  // namespace

Buckets::Buckets(const std::vector<std::size_t>& starts) : of(starts.size() - 1) {
  const std::size_t most = std::max(kBucketPoints, starts.back() / kBucketShare);
  std::size_t points = 0;
  for (std::uint32_t l = 0; l < of.size(); ++l) {
    const std::size_t count = starts[l + 1] - starts[l];
    if (first.empty() || l - first.back() >= kBucketLeaves ||
        (points > 0 && points + count > most)) {
      first.push_back(l);
      points = 0;
    }
    of[l] = static_cast<std::uint32_t>(first.size() - 1);
    points += count;
  }
  first.push_back(static_cast<std::uint32_t>(of.size()));
}

template <bool Quantised>
GroupedPoints groupPoints(const FrameData& frame, Grouping grouping) {
  std::optional<GroupedPoints> bucketed;
  if (grouping == Grouping::Any) bucketed = bucketedPoints<Quantised>(frame);
  return bucketed ? std::move(*bucketed) : sortedPoints<Quantised>(frame);
}

template GroupedPoints groupPoints<false>(const FrameData&, Grouping);
template GroupedPoints groupPoints<true>(const FrameData&, Grouping);

}  // namespace tickfx::io
