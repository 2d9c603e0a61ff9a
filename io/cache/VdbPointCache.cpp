#include "io/cache/VdbPointCache.h"

#include <openvdb/openvdb.h>
#include <openvdb/points/PointDataGrid.h>
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <numeric>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <thread>
#include <type_traits>
#include <utility>
#include <vector>

#include "fields/vdb/VdbGridFile.h"
#include "io/cache/AttributeGroups.h"
#include "io/cache/VdbPointCacheBytes.h"
#include "io/cache/VdbPointsEncoder.h"
#include "io/util/AtomicFile.h"
#include "io/util/Fingerprint.h"
#include "io/util/ProfiledTbb.h"
#include "particles/Isa.h"

namespace tickfx::io {
namespace {

namespace vdbp = openvdb::points;

const std::string kGridName = "points";
// Points whose coordinates are within this bound sit in their nearest voxel; beyond it (or not
// finite) in voxel 0 of that axis. Far inside the 32-bit voxel indices, with room for a tree's
// nodes around them.
constexpr double kLargestIndex = 1073741824.0;  // 2³⁰

const char* const kMetaEffectHash = "tickfx_effect_hash";
const char* const kMetaSeed = "tickfx_seed";
const char* const kMetaStepRate = "tickfx_step_rate";
const char* const kMetaIntegrator = "tickfx_integrator";
const char* const kMetaFrame = "tickfx_frame";
const char* const kMetaTime = "tickfx_time";
const char* const kMetaVersion = "tickfx_version";
const char* const kMetaPointCount = "tickfx_point_count";

using PositionArray = vdbp::TypedAttributeArray<openvdb::Vec3f, vdbp::NullCodec>;
using QuantisedPositionArray =
    vdbp::TypedAttributeArray<openvdb::Vec3f, vdbp::FixedPointCodec<false, vdbp::PositionRange>>;
using VectorArray = vdbp::TypedAttributeArray<openvdb::Vec3f, vdbp::NullCodec>;
using IdArray = vdbp::TypedAttributeArray<std::int64_t, vdbp::NullCodec>;
using FloatArray = vdbp::TypedAttributeArray<float, vdbp::NullCodec>;
using IntArray = vdbp::TypedAttributeArray<std::int32_t, vdbp::NullCodec>;

std::string where(const std::string& path) { return vdbGridLabel(path, kGridName); }

// ---- writing ---------------------------------------------------------------------------------

// One coordinate x as OpenVDB stores it: voxel index n and offset o with float(n + o) == x
// bitwise (the voxel size is 1), |o| <= 0.5 in the voxel nearest to x. When that is not exact
// (x beyond the bound, inf, nan; −0.0, whose sign no sum with n = 0 keeps) the coordinate goes
// whole into voxel 0.
// Coord::round's rule, floor(x + 0.5), for a finite |x| < 2³⁰, and x's offset from that voxel,
// in float alone (a float → double → float round trip is what g++ 12's vectoriser may fold
// away): x − floor(x) is exact, and so is x − n for the nearest integer n.
// The choice of n or n + 1 is made on the bits, not by a branch (on random positions it is a
// coin toss the processor would guess wrong half the time) nor by adding 0 (−0.0 + 0 is +0.0).
// floor(x) for |x| < 2³¹, sign of zero included, without a call or a branch: x86-64's baseline
// has no rounding instruction, so std::floor calls the C library. The truncation is exact (an |x|
// past 2²³ is whole already), its sign is put back for −0.0 and (−1, 0), and 1 is taken off a
// negative x's truncation when it is above x (subtracting +0 keeps the sign of −0.0).
[[gnu::always_inline]] inline float floorOf(float x) {
  const float truncated = std::copysign(static_cast<float>(static_cast<std::int32_t>(x)), x);
  const std::uint32_t above = 0u - static_cast<std::uint32_t>(truncated > x);
  return truncated - std::bit_cast<float>(std::bit_cast<std::uint32_t>(1.0f) & above);
}

[[gnu::always_inline]] inline std::pair<openvdb::Int32, float> nearestVoxel(float x) {
  const float down = floorOf(x);
  const std::uint32_t up = 0u - static_cast<std::uint32_t>(x - down >= 0.5f);
  const float n = std::bit_cast<float>((std::bit_cast<std::uint32_t>(down + 1.0f) & up) |
                                       (std::bit_cast<std::uint32_t>(down) & ~up));
  return {static_cast<openvdb::Int32>(n), x - n};
}

[[gnu::always_inline]] inline std::pair<openvdb::Int32, float> place(float x) {
  if (std::isfinite(x) && std::abs(x) < static_cast<float>(kLargestIndex)) {
    const auto [n, offset] = nearestVoxel(x);
    const float back = static_cast<float>(n) + offset;
    if (std::bit_cast<std::uint32_t>(back) == std::bit_cast<std::uint32_t>(x)) return {n, offset};
  }
  return {0, x};
}

// The attributes every cache has, in the order they are written; custom ones follow.
const std::vector<std::string>& standardAttributes() {
  static const std::vector<std::string> names = {"P", "v", "id", "age", "life", "mass"};
  return names;
}

bool isStandard(const std::string& name) {
  const std::vector<std::string>& names = standardAttributes();
  return std::find(names.begin(), names.end(), name) != names.end();
}

void checkAttributeName(const std::string& name) {
  if (isStandard(name)) {
    throw std::invalid_argument("custom attribute '" + name +
                                "' has the name of a standard attribute of a VDB points cache");
  }
  if (!vdbp::AttributeSet::Descriptor::validName(name)) {
    throw std::invalid_argument("custom attribute '" + name +
                                "' is not a valid OpenVDB attribute name (letters, digits, '_', "
                                "'|' and ':')");
  }
}

void checkColumns(const FrameData& frame) {
  const auto rows = static_cast<Eigen::Index>(frame.size());
  auto sized = [&](const FloatColumn& c) { return c.size() == rows; };
  bool ok = sized(frame.age) && sized(frame.life) && sized(frame.mass) &&
            frame.attributes.size() == frame.attributeNames.size();
  for (int c = 0; c < 3; ++c) ok = ok && sized(frame.position[c]) && sized(frame.velocity[c]);
  for (const FloatColumn& a : frame.attributes) ok = ok && sized(a);
  if (!ok) throw std::invalid_argument("frame columns of different lengths");
  for (const AttributeGroup& g : attributeGroups(frame.attributeNames)) checkAttributeName(g.name);
}

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

// A 16-bit fixed-point coordinate needs only its voxel and an offset within ±0.5, not the exact
// bits: the codec quantises the offset anyway (and turns a NaN into undefined behaviour).
[[gnu::always_inline]] inline std::pair<openvdb::Int32, float> placeQuantised(float x) {
  if (std::isnan(x)) return {0, 0.0f};
  if (!(std::abs(x) < static_cast<float>(kLargestIndex))) return {0, x > 0 ? 0.5f : -0.5f};
  return nearestVoxel(x);
}

// The frame's position columns, held apart from the frame: a loop that stores between two reads
// would otherwise read the columns' addresses from the frame again after every store.
struct Positions {
  std::array<const float*, 3> axis;
  explicit Positions(const FrameData& frame)
      : axis{frame.position.x.data(), frame.position.y.data(), frame.position.z.data()} {}

  // The voxel of row r (and its offset in that voxel, when asked), placed as the positions'
  // codec places it. Inlined into the placement loops, where a call would cost more.
  template <bool Quantised>
  [[gnu::always_inline]] openvdb::Coord voxel(std::size_t r,
                                              openvdb::Vec3f* offset = nullptr) const {
    openvdb::Coord voxel;
    for (int c = 0; c < 3; ++c) {
      const float x = axis[static_cast<std::size_t>(c)][r];
      const auto [index, o] = Quantised ? placeQuantised(x) : place(x);
      voxel[c] = index;
      if (offset != nullptr) (*offset)[c] = o;
    }
    return voxel;
  }
};

constexpr auto kLeafMask = ~static_cast<openvdb::Int32>(Leaf::DIM - 1);

// Rows placed kPlacedRows at a time by placeRows(): each axis's voxel indices and offsets.
constexpr std::size_t kPlacedRows = 512;
struct PlacedRows {
  std::array<std::array<std::int32_t, kPlacedRows>, 3> index;
  std::array<std::array<float, kPlacedRows>, 3> offset;

  openvdb::Coord voxel(std::size_t k) const { return {index[0][k], index[1][k], index[2][k]}; }
};

// Places rows [begin, begin + count) (count <= kPlacedRows) as Positions::voxel() places them,
// the same bits, in loops without branches or calls that the compiler vectorises: the
// coordinates outside the bound (or NaN) are placed as if they were 0, then their results
// replaced (the same rule as place(), placeQuantised() and nearestVoxel() above).
template <bool Quantised>
void placeRows(const Positions& positions, std::size_t begin, std::size_t count,
               PlacedRows& placed) {
  constexpr float kBound = static_cast<float>(kLargestIndex);
  for (std::size_t c = 0; c < 3; ++c) {
    const float* __restrict x = positions.axis[c] + begin;
    std::int32_t* __restrict index = placed.index[c].data();
    float* __restrict offset = placed.offset[c].data();
    for (std::size_t k = 0; k < count; ++k) {
      // Selections by masks, not ternaries: the compiler turns a ternary into a branch, which
      // random positions mispredict half the time, and does not vectorise it.
      const auto mask = [](bool b) { return 0u - static_cast<std::uint32_t>(b); };
      const auto bits = [](float f) { return std::bit_cast<std::uint32_t>(f); };
      const auto real = [](std::uint32_t u) { return std::bit_cast<float>(u); };
      const float v = x[k];
      const std::uint32_t inside = mask(std::abs(v) < kBound);  // false for NaN
      const float safe = real(bits(v) & inside);
      const float down = floorOf(safe);
      const std::uint32_t up = mask(safe - down >= 0.5f);
      const float n = real((bits(down + 1.0f) & up) | (bits(down) & ~up));  // −0.0 stays −0.0
      const auto i = static_cast<std::int32_t>(n);
      const float o = safe - n;
      std::uint32_t keep = inside;  // the rows placed by nearestVoxel()
      std::uint32_t otherwise = bits(v);
      if constexpr (Quantised) {
        otherwise = ((bits(v) & 0x80000000u) | bits(0.5f)) & ~mask(v != v);  // ±0.5, NaN 0
      } else {
        keep &= mask(bits(static_cast<float>(i) + o) == bits(v));
      }
      index[k] = static_cast<std::int32_t>(static_cast<std::uint32_t>(i) & keep);
      offset[k] = real((bits(o) & keep) | (otherwise & ~keep));
    }
  }
}

// A box of leaves: its first and last leaf origins, and its extent in leaves on each axis.
struct LeafBox {
  std::array<std::int32_t, 3> first{}, last{};
  std::array<std::uint32_t, 3> extent{};
};

// Each of the `count` placed rows' leaf index in `box` (x, then y, then z: Coord's order) in
// leaf[k], and false where some row's leaf lies outside the box (its index is then meaningless).
// In plain integer loops that the compiler vectorises; the box holds at most 2³² leaves, so the
// indices of the rows inside it fit 32 bits.
bool leafIndices(const PlacedRows& placed, std::size_t count, const LeafBox& box,
                 std::uint32_t* __restrict leaf) {
  constexpr unsigned kLeafLog2 = Leaf::LOG2DIM;
  std::uint32_t outside = 0;
  for (std::size_t k = 0; k < count; ++k) {
    std::uint32_t index = 0;
    for (std::size_t c = 0; c < 3; ++c) {
      const std::int32_t origin = placed.index[c][k] & kLeafMask;
      outside |= static_cast<std::uint32_t>(origin < box.first[c]) |
                 static_cast<std::uint32_t>(origin > box.last[c]);
      // (Unsigned: exact for a leaf in the box, where first <= origin <= last.)
      index = index * box.extent[c] +
              ((static_cast<std::uint32_t>(origin) - static_cast<std::uint32_t>(box.first[c])) >>
               kLeafLog2);
    }
    leaf[k] = index;
  }
  return outside == 0;
}

// placeRows() and leafIndices() compiled for each instruction set (particles/Isa.h), whole
// (flatten): the same bits on each, as they use integer operations and IEEE arithmetic alone.
#ifdef TICKFX_AVX2_CLONES
template <bool Quantised>
[[gnu::target("avx2"), gnu::flatten]] void placeRowsAvx2(const Positions& positions,
                                                         std::size_t begin, std::size_t count,
                                                         PlacedRows& placed) {
  placeRows<Quantised>(positions, begin, count, placed);
}
template <bool Quantised>
[[gnu::target("avx2,avx512f"), gnu::flatten]] void placeRowsAvx512(const Positions& positions,
                                                                   std::size_t begin,
                                                                   std::size_t count,
                                                                   PlacedRows& placed) {
  placeRows<Quantised>(positions, begin, count, placed);
}
[[gnu::target("avx2"), gnu::flatten]] bool leafIndicesAvx2(const PlacedRows& placed,
                                                           std::size_t count, const LeafBox& box,
                                                           std::uint32_t* leaf) {
  return leafIndices(placed, count, box, leaf);
}
[[gnu::target("avx2,avx512f"), gnu::flatten]] bool leafIndicesAvx512(const PlacedRows& placed,
                                                                     std::size_t count,
                                                                     const LeafBox& box,
                                                                     std::uint32_t* leaf) {
  return leafIndices(placed, count, box, leaf);
}
#endif

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
// more. Rows are first scattered by bucket (some 140 streams at 10⁶ and 10⁷ points over a 100 m
// box, where a scatter by leaf wrote 2200 and missed the cache on nearly every value), each
// bucket's rows in row order; then each bucket, small enough for the cache, is put in order by
// leaf and voxel.
constexpr std::size_t kBucketPoints = 8192;
constexpr std::size_t kBucketShare = 128;
constexpr std::uint32_t kBucketLeaves = 16;
constexpr unsigned kVoxelBits = 3 * Leaf::LOG2DIM;  // a voxel's index in its leaf
static_assert(std::size_t{1} << kVoxelBits == Leaf::SIZE);
static_assert((kBucketLeaves << kVoxelBits) - 1 <= std::numeric_limits<std::uint16_t>::max(),
              "a point's key in its bucket (leaf, voxel) fits the voxel column's 16 bits");

// The buckets of leaves whose points start at `starts` (and end at its last entry): first[b] is
// bucket b's first leaf (first[count()] the number of leaves), of[l] the bucket of leaf l.
struct Buckets {
  std::vector<std::uint32_t> first, of;

  Buckets() = default;
  explicit Buckets(const std::vector<std::size_t>& starts) : of(starts.size() - 1) {
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
  std::size_t count() const { return first.size() - 1; }
};

// The points in the order the leaves' arrays hold them: the leaves in Coord order (ascending, as
// Coord's operator< orders them), a leaf's points by voxel, and in row order within a voxel. Each
// point's values are copied here in that order, so that a leaf's array is one stretch of each
// column, written to the file as it is.
struct GroupedPoints {
  std::vector<std::size_t> starts;  // each leaf's first point, and the end
  std::vector<openvdb::Coord> origins;
  // (Large arrays: in a virtual machine, faulting in 4 KiB pages cost more than the copying.)
  LargeArray<std::uint16_t> voxel;    // a point's voxel in its leaf (0 to 511)
  LargeArray<openvdb::Vec3f> offset;  // its position's offset in the voxel
  LargeArray<std::uint64_t> id;
  // velocity x, y, z, age, life, mass, then the frame's attributes (pointFloatColumns' order)
  std::vector<LargeArray<float>> columns;
  // Where set (bucketedPoints), `id` and `columns` are put in order bucket by bucket by the store
  // itself, as the file is written (orderLater()): each bucket's rows of them are still in row
  // order, rank[k] the place in its bucket of the point whose values are at row k, and
  // later[b * laterColumns() + s] tells whether bucket b's column s (0: id, then columns[s − 1])
  // is in order (kOrdered), being put in order (kOrdering) or not yet.
  LargeArray<std::uint32_t> rank;
  Buckets buckets;
  std::unique_ptr<std::atomic<std::uint8_t>[]> later;

  GroupedPoints(std::size_t n, std::size_t floatColumnCount)
      : voxel(allocateLargeArray<std::uint16_t>(n)),
        offset(allocateLargeArray<openvdb::Vec3f>(n)),
        id(allocateLargeArray<std::uint64_t>(n)) {
    for (std::size_t j = 0; j < floatColumnCount; ++j)
      columns.push_back(allocateLargeArray<float>(n));
  }
  // The columns `later` tells of for each bucket: the ids, then the float columns.
  std::size_t laterColumns() const { return 1 + columns.size(); }
  // The points of bucket b: [first, second).
  std::pair<std::size_t, std::size_t> bucketPoints(std::size_t b) const {
    return {starts[buckets.first[b]], starts[buckets.first[b + 1]]};
  }
};

constexpr std::size_t kStandardFloatColumns = 6;  // velocity x, y, z, age, life, mass

std::vector<const float*> pointFloatColumns(const FrameData& frame) {
  std::vector<const float*> columns = {frame.velocity[0].data(), frame.velocity[1].data(),
                                       frame.velocity[2].data(), frame.age.data(),
                                       frame.life.data(),        frame.mass.data()};
  for (const FloatColumn& a : frame.attributes) columns.push_back(a.data());
  return columns;
}

// The general way: every point's slot, sorted by (leaf, voxel, row).
template <bool Quantised>
GroupedPoints sortedPoints(const FrameData& frame) {
  std::vector<PointSlot> slots = slotsInRowOrder<Quantised>(frame);
  if (!sortByKeys(slots)) par::parallel_sort(slots.begin(), slots.end());
  const std::vector<const float*> source = pointFloatColumns(frame);
  GroupedPoints points(slots.size(), source.size());
  const Positions positions(frame);
  par::parallel_for(tbb::blocked_range<std::size_t>(0, slots.size(), kPlacementGrain),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t k = range.begin(); k < range.end(); ++k) {
                        const std::size_t r = slots[k].row;
                        points.voxel[k] = static_cast<std::uint16_t>(slots[k].voxel);
                        positions.voxel<Quantised>(r, &points.offset[k]);
                        points.id[k] = frame.id[r];
                        for (std::size_t j = 0; j < source.size(); ++j)
                          points.columns[j][k] = source[j][r];
                      }
                    });
  for (std::size_t k = 0; k < slots.size(); ++k) {
    if (k == 0 || slots[k].leaf != slots[k - 1].leaf) {
      points.starts.push_back(k);
      points.origins.push_back(slots[k].leaf);
    }
  }
  points.starts.push_back(slots.size());
  return points;
}

// to[at[i]] = from[i] for rows [begin, end).
template <typename T>
void scatter(const T* __restrict from, const std::uint32_t* __restrict at, std::size_t begin,
             std::size_t end, T* __restrict to) {
  for (std::size_t i = begin; i < end; ++i) to[at[i]] = from[i];
}

// Rows are bucketed in chunks of at least this many, at most kMaxChunks chunks.
constexpr std::size_t kBucketChunk = 65536;
constexpr std::size_t kMaxChunks = 64;

// Extends [low, high] over the coordinates x[begin, end) below 2³⁰ in magnitude, and returns
// whether some other coordinate (beyond, infinite or NaN: placed at 0) is among them. A
// register's lanes of bounds at once, folded at the end (min and max give the same bounds in any
// order; a zero's sign may differ, and both zeros lie in the same voxel).
using Floats4 = float __attribute__((vector_size(16)));
using Floats8 = float __attribute__((vector_size(32)));
using Floats16 = float __attribute__((vector_size(64)));
using Ints4 = std::int32_t __attribute__((vector_size(16)));
using Ints8 = std::int32_t __attribute__((vector_size(32)));
using Ints16 = std::int32_t __attribute__((vector_size(64)));

template <typename Floats, typename Bits>
bool extendBoundsBy(const float* x, std::size_t begin, std::size_t end, float& low, float& high) {
  constexpr int Lanes = sizeof(Floats) / sizeof(float);
  static_assert(sizeof(Bits) == sizeof(Floats));
  constexpr auto kLimit = static_cast<float>(kLargestIndex);
  Floats limit, lows, highs;
  for (int k = 0; k < Lanes; ++k) {
    limit[k] = kLimit;
    lows[k] = low;
    highs[k] = high;
  }
  Bits outside = {};
  std::size_t i = begin;
  for (; i + Lanes <= end; i += Lanes) {
    Floats v;
    std::memcpy(&v, x + i, sizeof v);
    const Bits bits = __builtin_bit_cast(Bits, v);
    const Bits inside = __builtin_bit_cast(Floats, bits & 0x7fffffff) < limit;  // all ones; not NaN
    const Bits lower = inside & (v < lows), higher = inside & (v > highs);
    lows = __builtin_bit_cast(Floats, (bits & lower) | (__builtin_bit_cast(Bits, lows) & ~lower));
    highs =
        __builtin_bit_cast(Floats, (bits & higher) | (__builtin_bit_cast(Bits, highs) & ~higher));
    outside |= ~inside;
  }
  bool beyond = false;
  for (int k = 0; k < Lanes; ++k) {
    low = std::min(low, lows[k]);
    high = std::max(high, highs[k]);
    beyond |= outside[k] != 0;
  }
  for (; i < end; ++i) {
    const bool inside = std::abs(x[i]) < kLimit;  // not NaN
    low = std::min(low, inside ? x[i] : low);
    high = std::max(high, inside ? x[i] : high);
    beyond |= !inside;
  }
  return beyond;
}

#ifdef TICKFX_AVX2_CLONES
[[gnu::target("avx2"), gnu::flatten]] bool extendBoundsAvx2(const float* x, std::size_t begin,
                                                            std::size_t end, float& low,
                                                            float& high) {
  return extendBoundsBy<Floats8, Ints8>(x, begin, end, low, high);
}
[[gnu::target("avx2,avx512f"), gnu::flatten]] bool extendBoundsAvx512(const float* x,
                                                                      std::size_t begin,
                                                                      std::size_t end, float& low,
                                                                      float& high) {
  return extendBoundsBy<Floats16, Ints16>(x, begin, end, low, high);
}
#endif

// The bounds', placement and leaf index loops above on one instruction set, the widest here,
// chosen once (activeIsa()).
template <bool Quantised>
struct RowKernels {
  using Bounds = bool (*)(const float*, std::size_t, std::size_t, float&, float&);
  using Place = void (*)(const Positions&, std::size_t, std::size_t, PlacedRows&);
  using Index = bool (*)(const PlacedRows&, std::size_t, const LeafBox&, std::uint32_t*);
  Bounds bounds = &extendBoundsBy<Floats4, Ints4>;
  Place place = &placeRows<Quantised>;
  Index index = &leafIndices;

  RowKernels() {
#ifdef TICKFX_AVX2_CLONES
    switch (activeIsa()) {
      case Isa::Avx512:
        bounds = &extendBoundsAvx512;
        place = &placeRowsAvx512<Quantised>;
        index = &leafIndicesAvx512;
        break;
      case Isa::Avx2:
        bounds = &extendBoundsAvx2;
        place = &placeRowsAvx2<Quantised>;
        index = &leafIndicesAvx2;
        break;
      case Isa::Baseline:
        break;
    }
#endif
  }
};

// What orderBucket() reuses from one bucket to the next.
struct BucketScratch {
  std::vector<std::uint32_t> counts;
  std::vector<std::uint16_t> keys;
  std::vector<openvdb::Vec3f> vectors;
  std::vector<std::uint64_t> ids;
  std::vector<float> floats;
};

// column[rank[i]] = column[i] for i < count, through a copy.
template <typename T>
void permute(T* __restrict column, const std::uint32_t* __restrict rank, std::size_t count,
             std::vector<T>& copy) {
  copy.assign(column, column + count);
  for (std::size_t i = 0; i < count; ++i) column[rank[i]] = copy[i];
}

// Puts bucket b's points, in row order and with a voxel column that holds
// each point's key (its leaf's place in the bucket, then its voxel), in order by key, rows in
// order among equal keys (a counting sort): the voxel column then holds each point's voxel, and
// the offsets are moved alike. Each point's place is kept in `rank` for the columns the store
// puts in order later (orderLater()).
void orderBucket(GroupedPoints& points, std::size_t b, BucketScratch& scratch) {
  const auto [begin, end] = points.bucketPoints(b);
  const std::size_t count = end - begin;
  const std::size_t leaves = points.buckets.first[b + 1] - points.buckets.first[b];
  std::uint16_t* const key = points.voxel.get() + begin;
  scratch.counts.assign(leaves << kVoxelBits, 0);
  for (std::size_t i = 0; i < count; ++i) ++scratch.counts[key[i]];
  std::uint32_t sum = 0;
  for (std::uint32_t& c : scratch.counts) sum += std::exchange(c, sum);
  std::uint32_t* const rank = points.rank.get() + begin;
  for (std::size_t i = 0; i < count; ++i) rank[i] = scratch.counts[key[i]]++;
  permute(key, rank, count, scratch.keys);
  for (std::size_t i = 0; i < count; ++i) key[i] &= Leaf::SIZE - 1;  // the voxel alone
  permute(points.offset.get() + begin, rank, count, scratch.vectors);
}

constexpr std::uint8_t kOrdering = 1, kOrdered = 2;

// Puts column s (0: id, then columns[s − 1]) of bucket b in order, once: the first thread to
// ask does it, another that asks meanwhile waits for it (it is running, and takes microseconds).
// The store asks before reading a leaf's values (GroupedValues), so this runs beside the
// kernel's copy of the chunk before, in time the writing threads would otherwise wait.
void orderLater(GroupedPoints& points, std::size_t b, std::size_t s, BucketScratch& scratch) {
  std::atomic<std::uint8_t>& state = points.later[b * points.laterColumns() + s];
  if (state.load(std::memory_order_acquire) == kOrdered) return;
  std::uint8_t expected = 0;
  if (!state.compare_exchange_strong(expected, kOrdering, std::memory_order_acquire)) {
    while (state.load(std::memory_order_acquire) != kOrdered) std::this_thread::yield();
    return;
  }
  const auto [begin, end] = points.bucketPoints(b);
  const std::size_t count = end - begin;
  const std::uint32_t* const rank = points.rank.get() + begin;
  try {
    if (s == 0)
      permute(points.id.get() + begin, rank, count, scratch.ids);
    else
      permute(points.columns[s - 1].get() + begin, rank, count, scratch.floats);
  } catch (...) {
    state.store(0, std::memory_order_release);  // (an allocation failed: another may try)
    throw;
  }
  state.store(kOrdered, std::memory_order_release);
}

// Every column in order (OpenVDB's own writer reads the grouped points whole).
void orderAllLater(GroupedPoints& points) {
  if (!points.later) return;
  par::parallel_for(tbb::blocked_range<std::size_t>(0, points.buckets.count()),
                    [&](const tbb::blocked_range<std::size_t>& some) {
                      BucketScratch scratch;
                      for (std::size_t b = some.begin(); b < some.end(); ++b)
                        for (std::size_t s = 0; s < points.laterColumns(); ++s)
                          orderLater(points, b, s, scratch);
                    });
}

// The fast way, when the leaves' bounding box holds few enough leaves to count them in a table
// (any effect of sane size): a stable counting sort of the rows by the leaf's index in the box
// (x, then y, then z: Coord's order), in two steps: by bucket of leaves, then within each bucket
// by leaf and voxel (Buckets, orderBucket). The chunks are fixed by the point count alone (the
// order depends on neither them nor the threads). Nothing otherwise.
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
  const std::size_t chunks = std::clamp<std::size_t>(n / kBucketChunk, 1, kMaxChunks);
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
  const std::vector<const float*> source = pointFloatColumns(frame);
  GroupedPoints points(n, source.size());
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
    points.origins.push_back(box.first +
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
  par::parallel_for(tbb::blocked_range<std::size_t>(0, chunks, 1),
                    [&](const tbb::blocked_range<std::size_t>& run) {
                      std::uint32_t* const at = rowAt.get();
                      std::uint16_t* const __restrict key = points.voxel.get();
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
                            key[to] = static_cast<std::uint16_t>(
                                ((p & 15) << kVoxelBits) |
                                static_cast<std::uint32_t>(Leaf::coordToOffset(placed.voxel(k))));
                            offset[to] = openvdb::Vec3f(placed.offset[0][k], placed.offset[1][k],
                                                        placed.offset[2][k]);
                          }
                        }
                      }
                      const std::size_t runBegin = chunkRange(run.begin()).first;
                      const std::size_t runEnd = chunkRange(run.end() - 1).second;
                      scatter(frame.id.data(), at, runBegin, runEnd, points.id.get());
                      for (std::size_t j = 0; j < source.size(); ++j)
                        scatter(source[j], at, runBegin, runEnd, points.columns[j].get());
                    });
  // Each bucket (in cache) in order by key: by leaf, then voxel, rows in order within a voxel.
  points.rank = allocateLargeArray<std::uint32_t>(n);
  points.buckets = std::move(buckets);
  par::parallel_for(tbb::blocked_range<std::size_t>(0, bucketCount),
                    [&](const tbb::blocked_range<std::size_t>& some) {
                      BucketScratch scratch;
                      for (std::size_t b = some.begin(); b < some.end(); ++b)
                        orderBucket(points, b, scratch);
                    });
  const std::size_t later = bucketCount * points.laterColumns();
  points.later = std::make_unique<std::atomic<std::uint8_t>[]>(later);  // (zeroed: not yet)
  return points;
}

// What an attribute of the grid holds, in the descriptor's order: P, v, id, age, life, mass, then
// the frame's attribute groups as Houdini's typed attributes (hitnum an int32, hitpos a vec3s).
// `column`: the first of GroupedPoints::columns it reads (a vector reads three).
struct GridAttribute {
  enum class Kind { Position, Vector, Id, Float, Int };
  std::string name;
  Kind kind = Kind::Float;
  std::size_t column = 0;

  // How many of GroupedPoints::columns it reads, from `column` on (the offsets and the ids are
  // columns apart).
  std::size_t floatColumns() const {
    return kind == Kind::Vector ? 3 : kind == Kind::Float || kind == Kind::Int ? 1 : 0;
  }
};

// The grid's attributes of a frame with these attribute columns.
std::vector<GridAttribute> gridAttributes(const std::vector<std::string>& attributeNames) {
  using Kind = GridAttribute::Kind;
  const std::vector<std::string>& standard = standardAttributes();  // P, v, id, age, life, mass
  std::vector<GridAttribute> attributes = {
      {standard[0], Kind::Position, 0}, {standard[1], Kind::Vector, 0},
      {standard[2], Kind::Id, 0},       {standard[3], Kind::Float, 3},
      {standard[4], Kind::Float, 4},    {standard[5], Kind::Float, 5}};
  for (const AttributeGroup& g : attributeGroups(attributeNames)) {
    const Kind kind = g.kind == AttributeKind::Vec3  ? Kind::Vector
                      : g.kind == AttributeKind::Int ? Kind::Int
                                                     : Kind::Float;
    attributes.push_back({g.name, kind, kStandardFloatColumns + g.column});
  }
  return attributes;
}

// Calls f(std::type_identity<Array>()) with the array type of attributes of `kind`.
template <typename PositionArray, typename F>
void withArrayType(GridAttribute::Kind kind, const F& f) {
  using Kind = GridAttribute::Kind;
  switch (kind) {
    case Kind::Position:
      return f(std::type_identity<PositionArray>());
    case Kind::Vector:
      return f(std::type_identity<VectorArray>());
    case Kind::Id:
      return f(std::type_identity<IdArray>());
    case Kind::Int:
      return f(std::type_identity<IntArray>());
    case Kind::Float:
      return f(std::type_identity<FloatArray>());
  }
}

// The grid's descriptor: each attribute's name and its array's type, P first.
template <typename PositionArray>
vdbp::AttributeSet::Descriptor::Ptr gridDescriptor(const std::vector<GridAttribute>& attributes) {
  auto descriptor = vdbp::AttributeSet::Descriptor::create(PositionArray::attributeType());
  for (std::size_t a = 1; a < attributes.size(); ++a) {
    withArrayType<PositionArray>(
        attributes[a].kind, [&]<typename Array>(std::type_identity<Array>) {
          descriptor = descriptor->duplicateAppend(attributes[a].name, Array::attributeType());
        });
  }
  return descriptor;
}

// Sets leaf l's voxel values, each the end of its voxel's points in the leaf's arrays, and its
// value mask, on where a voxel holds points: what setOffsets(ends, /*updateValueMask=*/true)
// sets, without its two calls a voxel.
void setVoxelEnds(const GroupedPoints& points, std::size_t l, Leaf& leaf) {
  std::array<openvdb::Index32, Leaf::SIZE> counts{};
  for (std::size_t k = points.starts[l]; k < points.starts[l + 1]; ++k) ++counts[points.voxel[k]];
  openvdb::PointDataIndex32* const ends = leaf.buffer().data();
  Leaf::NodeMaskType mask;  // all off
  openvdb::Index32 sum = 0;
  for (openvdb::Index w = 0; w < Leaf::NodeMaskType::WORD_COUNT; ++w) {
    std::uint64_t word = 0;
    for (openvdb::Index b = 0; b < 64; ++b) {
      const openvdb::Index32 count = counts[64 * w + b];
      word |= std::uint64_t{count > 0} << b;
      ends[64 * w + b] = sum += count;
    }
    mask.template getWord<std::uint64_t>(w) = word;
  }
  leaf.setValueMask(mask);
}

// Leaf l with its voxel values, and its default attribute set: encodePointsFile takes
// placeholders on the tree's first leaf alone, some ten thousand arrays fewer to make and free
// at 10⁶ points.
std::unique_ptr<Leaf> makeEmptyLeaf(const GroupedPoints& points, std::size_t l) {
  auto leaf = std::make_unique<Leaf>(points.origins[l]);
  setVoxelEnds(points, l, *leaf);
  return leaf;
}

// Gives `leaf` an attribute set of its point count, each array uniform: the placeholders
// encodePointsFile takes, or arrays to be expanded and filled.
void addUniformArrays(Leaf& leaf, const vdbp::AttributeSet::Descriptor::Ptr& descriptor) {
  // (initializeAttributes takes a descriptor of P alone; this one has every attribute.)
  leaf.replaceAttributeSet(
      new vdbp::AttributeSet(descriptor, static_cast<openvdb::Index>(leaf.pointCount())),
      /*allowMismatchingDescriptors=*/true);
}

// Calls set(k, value) for each point k of leaf l in its array's order, with the value attribute
// `a` holds for it.
template <typename Set>
void eachValue(const GroupedPoints& points, std::size_t l, const GridAttribute& a, const Set& set) {
  using Kind = GridAttribute::Kind;
  const std::size_t begin = points.starts[l];
  const std::size_t count = points.starts[l + 1] - begin;
  const auto column = [&](std::size_t j) { return points.columns[a.column + j].get() + begin; };
  switch (a.kind) {
    case Kind::Position: {
      const openvdb::Vec3f* offset = points.offset.get() + begin;
      for (std::size_t k = 0; k < count; ++k) set(k, offset[k]);
      return;
    }
    case Kind::Vector: {
      const float *x = column(0), *y = column(1), *z = column(2);
      for (std::size_t k = 0; k < count; ++k) {
        set(k, openvdb::Vec3f(x[k], y[k], z[k]));
      }
      return;
    }
    case Kind::Id: {
      const std::uint64_t* id = points.id.get() + begin;
      for (std::size_t k = 0; k < count; ++k) set(k, static_cast<std::int64_t>(id[k]));
      return;
    }
    case Kind::Int: {
      const float* x = column(0);
      for (std::size_t k = 0; k < count; ++k) set(k, static_cast<std::int32_t>(x[k]));
      return;
    }
    case Kind::Float: {
      const float* x = column(0);
      for (std::size_t k = 0; k < count; ++k) set(k, x[k]);
      return;
    }
  }
}

// The array at `pos` of `leaf` as its own type, expanded to one value a point (each is then
// set: no fill). Typed access calls the codec inline, where a handle calls through a pointer.
template <typename Array>
Array& expandedArray(Leaf& leaf, std::size_t pos) {
  auto& array = static_cast<Array&>(leaf.attributeArray(pos));
  array.expand(/*fill=*/false);
  return array;
}

// Leaf l of `points`, every attribute filled through its array: what OpenVDB's own writer
// takes, the reference that the bytes GroupedValues stores are held to.
template <typename PositionArray>
std::unique_ptr<Leaf> makeLeaf(const std::vector<GridAttribute>& attributes,
                               const GroupedPoints& points, std::size_t l,
                               const vdbp::AttributeSet::Descriptor::Ptr& descriptor) {
  std::unique_ptr<Leaf> leaf = makeEmptyLeaf(points, l);
  addUniformArrays(*leaf, descriptor);
  for (std::size_t pos = 0; pos < attributes.size(); ++pos) {
    const auto fill = [&]<typename Array>(Array& array) {
      eachValue(points, l, attributes[pos], [&](std::size_t k, const auto& value) {
        if constexpr (std::is_convertible_v<decltype(value), typename Array::ValueType>)
          array.setUnsafe(static_cast<openvdb::Index>(k), value);
        else
          throw std::logic_error("VDB points: an attribute's values are not of its array's type");
      });
    };
    withArrayType<PositionArray>(
        attributes[pos].kind,
        [&]<typename Array>(std::type_identity<Array>) { fill(expandedArray<Array>(*leaf, pos)); });
  }
  return leaf;
}

// The grid's values, from the grouped points straight into the file's bytes: each encoded by its
// array's codec and stored as the array would store it.
template <typename PositionArray>
class GroupedValues final : public PointValues {
 public:
  GroupedValues(GroupedPoints& points, std::vector<GridAttribute> attributes)
      : points_(points), attributes_(std::move(attributes)) {}

  void store(std::size_t attribute, const openvdb::Coord& origin, std::size_t count,
             char* to) const override {
    Local& local = local_.local();
    const std::size_t l = leafAt(origin, local.next);
    if (points_.starts[l + 1] - points_.starts[l] != count || attribute >= attributes_.size())
      throw std::logic_error("VDB points: values asked for a leaf the frame does not have");
    local.next = l + 1;
    const GridAttribute& a = attributes_[attribute];
    if (points_.later) orderColumns(l, a, local.scratch);
    withArrayType<PositionArray>(
        a.kind, [&]<typename Array>(std::type_identity<Array>) { storeAs<Array>(l, a, to); });
  }

 private:
  // A thread's own: the leaf after the last it stored (the encoder asks for leaves in the tree's
  // order, which is nearly always the leaves' Coord order), and orderLater()'s scratch.
  struct Local {
    std::size_t next = 0;
    BucketScratch scratch;
  };

  // The index of the leaf at `origin`, tried first at `guess`.
  std::size_t leafAt(const openvdb::Coord& origin, std::size_t guess) const {
    const auto& origins = points_.origins;
    if (guess < origins.size() && origins[guess] == origin) return guess;
    const auto leaf = std::lower_bound(origins.begin(), origins.end(), origin);
    if (leaf == origins.end() || *leaf != origin)
      throw std::logic_error("VDB points: values asked for a leaf the frame does not have");
    return static_cast<std::size_t>(leaf - origins.begin());
  }

  // The columns attribute `a` reads, in order in leaf l's bucket (the offsets are ordered with
  // the voxels).
  void orderColumns(std::size_t l, const GridAttribute& a, BucketScratch& scratch) const {
    const std::size_t b = points_.buckets.of[l];
    if (a.kind == GridAttribute::Kind::Id) orderLater(points_, b, 0, scratch);
    for (std::size_t j = 0; j < a.floatColumns(); ++j)
      orderLater(points_, b, 1 + a.column + j, scratch);
  }

  template <typename Array>
  void storeAs(std::size_t l, const GridAttribute& a, char* to) const {
    using Storage = typename Array::StorageType;
    eachValue(points_, l, a, [&](std::size_t k, const auto& value) {
      if constexpr (std::is_convertible_v<decltype(value), typename Array::ValueType>) {
        Storage stored;
        Array::Codec::encode(typename Array::ValueType(value), stored);
        std::memcpy(to + k * sizeof(Storage), &stored, sizeof(Storage));
      } else {
        throw std::logic_error("VDB points: an attribute's values are not of its array's type");
      }
    });
  }

  GroupedPoints& points_;
  std::vector<GridAttribute> attributes_;
  mutable tbb::enumerable_thread_specific<Local> local_;
};

// Which way the points are grouped: only tests ask for the general way.
enum class Grouping { Any, Sorted };

template <typename PositionArray>
GroupedPoints groupedPoints(const FrameData& frame, Grouping grouping) {
  constexpr bool kQuantised = !std::is_same_v<typename PositionArray::Codec, vdbp::NullCodec>;
  std::optional<GroupedPoints> bucketed;
  if (grouping == Grouping::Any) bucketed = bucketedPoints<kQuantised>(frame);
  return bucketed ? std::move(*bucketed) : sortedPoints<kQuantised>(frame);
}

// The tree of `points`, each leaf made by makeLeaf(l). Leaves are independent: made in parallel
// (as OpenVDB's point conversion does), then handed to the tree in order.
template <typename MakeLeaf>
vdbp::PointDataTree::Ptr makeTree(const GroupedPoints& points, const MakeLeaf& makeLeaf) {
  std::vector<std::unique_ptr<Leaf>> leaves(points.origins.size());
  par::parallel_for(tbb::blocked_range<std::size_t>(0, leaves.size()),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t l = range.begin(); l < range.end(); ++l)
                        leaves[l] = makeLeaf(l);
                    });
  auto tree = std::make_shared<vdbp::PointDataTree>();
  for (std::unique_ptr<Leaf>& leaf : leaves) tree->addLeaf(leaf.release());
  return tree;
}

vdbp::PointDataGrid::Ptr makeGrid(const vdbp::PointDataTree::Ptr& tree, const FrameData& frame,
                                  const VdbCacheMetadata& meta) {
  auto grid = vdbp::PointDataGrid::create(tree);
  grid->setName(kGridName);
  grid->setTransform(openvdb::math::Transform::createLinearTransform(1.0));
  grid->insertMeta(kMetaEffectHash, openvdb::StringMetadata(meta.effectHash));
  grid->insertMeta(kMetaSeed, openvdb::Int64Metadata(static_cast<std::int64_t>(meta.seed)));
  grid->insertMeta(kMetaStepRate, openvdb::Int64Metadata(meta.stepRateHz));
  grid->insertMeta(kMetaIntegrator, openvdb::StringMetadata(meta.integrator));
  grid->insertMeta(kMetaFrame, openvdb::Int64Metadata(frame.frame));
  grid->insertMeta(kMetaTime, openvdb::DoubleMetadata(frame.timeSeconds));
  grid->insertMeta(kMetaVersion, openvdb::StringMetadata(meta.tickfxVersion));
  grid->insertMeta(kMetaPointCount,
                   openvdb::Int64Metadata(static_cast<std::int64_t>(frame.size())));
  return grid;
}

std::uint32_t compressionFlags(const VdbCacheOptions& options);

// The file, but for the UUID, handed to use(file) while what it is made from lives: the grid's
// leaves hold placeholders, and the values go from the grouped points straight into the bytes
// (encodePointsFile's PointValues) as the file is written (EncodedPointsFile).
template <typename PositionArray, typename Use>
void encodeFrame(const FrameData& frame, const VdbCacheMetadata& meta,
                 const VdbCacheOptions& options, Grouping grouping, const Use& use) {
  GroupedPoints points = groupedPoints<PositionArray>(frame, grouping);
  std::vector<GridAttribute> attributes = gridAttributes(frame.attributeNames);
  const auto descriptor = gridDescriptor<PositionArray>(attributes);
  auto tree = makeTree(points, [&](std::size_t l) { return makeEmptyLeaf(points, l); });
  // The placeholders, on the tree's first leaf (the tree's order is not the leaves' Coord order
  // where they lie far apart).
  if (auto first = tree->beginLeaf()) addUniformArrays(*first, descriptor);
  const vdbp::PointDataGrid::Ptr grid = makeGrid(tree, frame, meta);
  const GroupedValues<PositionArray> values(points, std::move(attributes));
  EncodedPointsFile file = encodePointsFile(*grid, compressionFlags(options), values);
  use(file);
}

// The grid with every array filled, as OpenVDB's own writer takes it.
template <typename PositionArray>
vdbp::PointDataGrid::Ptr filledGrid(const FrameData& frame, const VdbCacheMetadata& meta,
                                    Grouping grouping) {
  GroupedPoints points = groupedPoints<PositionArray>(frame, grouping);
  orderAllLater(points);
  const std::vector<GridAttribute> attributes = gridAttributes(frame.attributeNames);
  const auto descriptor = gridDescriptor<PositionArray>(attributes);
  return makeGrid(makeTree(points,
                           [&](std::size_t l) {
                             return makeLeaf<PositionArray>(attributes, points, l, descriptor);
                           }),
                  frame, meta);
}

template <typename Use>
void encodeFrame(const FrameData& frame, const VdbCacheMetadata& meta,
                 const VdbCacheOptions& options, Grouping grouping, const Use& use) {
  checkColumns(frame);
  if (options.positions == VdbCacheOptions::Positions::Fixed16)
    encodeFrame<QuantisedPositionArray>(frame, meta, options, grouping, use);
  else
    encodeFrame<PositionArray>(frame, meta, options, grouping, use);
}

vdbp::PointDataGrid::Ptr filledGrid(const FrameData& frame, const VdbCacheMetadata& meta,
                                    const VdbCacheOptions& options, Grouping grouping) {
  checkColumns(frame);
  return options.positions == VdbCacheOptions::Positions::Fixed16
             ? filledGrid<QuantisedPositionArray>(frame, meta, grouping)
             : filledGrid<PositionArray>(frame, meta, grouping);
}

// ---- reading ---------------------------------------------------------------------------------

template <typename T>
std::optional<T> metaValue(const openvdb::GridBase& grid, const char* name) {
  using Meta = openvdb::TypedMetadata<T>;
  if (const auto m = grid.getMetadata<Meta>(name)) return m->value();
  return std::nullopt;
}

// True when `transform` maps every index to the same world coordinates, exactly.
bool isIdentity(const openvdb::math::Transform& transform) {
  if (!transform.isLinear()) return false;
  for (const openvdb::Vec3d& x :
       {openvdb::Vec3d(0, 0, 0), openvdb::Vec3d(1, 0, 0), openvdb::Vec3d(0, 1, 0),
        openvdb::Vec3d(0, 0, 1), openvdb::Vec3d(-3, 5, 7)}) {
    if (transform.indexToWorld(x) != x) return false;
  }
  return true;
}

// The file's compression flags (openvdb::io::COMPRESS_*), as io::File would take them.
std::uint32_t compressionFlags(const VdbCacheOptions& options) {
  return options.compression == VdbCacheOptions::Compression::Blosc
             ? openvdb::io::COMPRESS_BLOSC | openvdb::io::COMPRESS_ACTIVE_MASK
             : openvdb::io::COMPRESS_ACTIVE_MASK;
}

// Room for a whole file (uncompressed): the arrays' bytes, a leaf's offsets and masks (at most
// 2 + 4 KiB), and the headers.
std::size_t expectedFileBytes(const FrameData& frame, const vdbp::PointDataGrid& grid) {
  const std::size_t bytesPerPoint = 12 + 12 + 8 + 4 * (3 + frame.attributes.size());
  return frame.size() * bytesPerPoint + grid.constTree().leafCount() * (6 * 1024) + (64 << 10);
}

// OpenVDB stamps every file with a random UUID (36 characters after the header's version fields),
// so two identical runs would write different bytes. A cache's UUID is made from what the file
// holds instead: the effect's fingerprint, its seed and the frame (an RFC 9562 version-8 UUID).
// The header layout is checked first; a layout this build does not know is left as written.
void stampUuid(std::span<char> bytes, const VdbCacheMetadata& meta, std::int64_t frame) {
  constexpr std::size_t kUuidAt = 21;
  constexpr std::size_t kUuidLength = 36;
  if (bytes.size() < kUuidAt + kUuidLength) return;
  const std::string_view uuid(bytes.data() + kUuidAt, kUuidLength);
  if (std::string_view(bytes.data(), 4) != " BDV" || uuid[8] != '-' || uuid[13] != '-' ||
      uuid[18] != '-' || uuid[23] != '-') {
    return;
  }
  const std::string key =
      meta.effectHash + '/' + std::to_string(meta.seed) + '/' + std::to_string(frame);
  const std::uint64_t hi = fingerprint(key + "/hi"), lo = fingerprint(key + "/lo");
  char text[kUuidLength + 1];
  std::snprintf(text, sizeof text, "%08x-%04x-8%03x-%04x-%012llx", static_cast<unsigned>(hi >> 32),
                static_cast<unsigned>((hi >> 16) & 0xffff), static_cast<unsigned>(hi & 0xfff),
                static_cast<unsigned>(0x8000 | ((lo >> 48) & 0x3fff)),
                static_cast<unsigned long long>(lo & 0xffffffffffffULL));
  std::memcpy(bytes.data() + kUuidAt, text, kUuidLength);
}

// What OpenVDB reads without comparing (readVdbGrid has checked every size it trusts): a leaf's
// voxel offsets must rise to its point count, and every attribute array must hold that many
// points, or the handles below would read past the arrays.
void checkLeaf(const vdbp::PointDataTree::LeafNodeType& leaf, const std::string& file) {
  openvdb::Index32 count = 0;
  for (openvdb::Index n = 0; n < vdbp::PointDataTree::LeafNodeType::SIZE; ++n) {
    const openvdb::Index32 end = leaf.getValue(n);
    if (end < count) {
      throw std::runtime_error(where(file) +
                               ": a leaf's point offsets decrease (the file is corrupt)");
    }
    count = end;
  }
  const vdbp::AttributeSet& set = leaf.attributeSet();
  for (std::size_t i = 0; i < set.size(); ++i) {
    const vdbp::AttributeArray* a = set.getConst(i);
    if (a == nullptr || a->size() != count || (!a->isUniform() && a->dataSize() < a->size())) {
      throw std::runtime_error(where(file) + ": a leaf's attributes do not hold its " +
                               std::to_string(count) + " points (the file is corrupt)");
    }
  }
}

}  // namespace

void writeVdbPointCache(const FrameData& frame, const VdbCacheMetadata& meta,
                        const std::filesystem::path& path, const VdbCacheOptions& options,
                        Durability durability) {
  openvdb::initialize();
  encodeFrame(frame, meta, options, Grouping::Any, [&](EncodedPointsFile& file) {
    stampUuid(std::span<char>(file.head(), file.headSize()), meta, frame.frame);
    writeFileAtomically(
        path, [&](std::ostream& out) { file.write(out); }, durability);
  });
}

namespace detail {

std::string vdbPointCacheBytes(const FrameData& frame, const VdbCacheMetadata& meta,
                               const VdbCacheOptions& options, VdbEncoder encoder,
                               VdbGrouping grouping) {
  openvdb::initialize();
  const Grouping by = grouping == VdbGrouping::Sorted ? Grouping::Sorted : Grouping::Any;
  std::string bytes;
  if (encoder == VdbEncoder::Parallel) {
    encodeFrame(frame, meta, options, by, [&](const EncodedPointsFile& file) {
      const FileBytes encoded = file.bytes();
      bytes.assign(encoded.data(), encoded.size());
    });
  } else {
    const vdbp::PointDataGrid::Ptr grid = filledGrid(frame, meta, options, by);
    bytes =
        encodePointsFileSerially(grid, compressionFlags(options), expectedFileBytes(frame, *grid));
  }
  stampUuid(bytes, meta, frame.frame);
  return bytes;
}

}  // namespace detail

FrameData readVdbPointCache(const std::filesystem::path& path, VdbCacheContents* contents) {
  const std::string file = path.string();
  openvdb::initialize();
  const openvdb::GridBase::Ptr base = readVdbGrid(file, kGridName);
  const auto grid = openvdb::gridPtrCast<vdbp::PointDataGrid>(base);
  if (!grid) {
    throw std::runtime_error(where(file) + ": is a grid of type " + base->type() +
                             " (expected a PointDataGrid)");
  }
  const vdbp::PointDataTree& tree = grid->constTree();
  const openvdb::math::Transform& transform = grid->constTransform();
  const bool identity = isIdentity(transform);

  VdbCacheContents found;
  std::vector<openvdb::Vec3f> position, velocity;
  std::vector<std::int64_t> id;
  std::vector<float> age, life, mass;
  std::vector<std::string> customNames;
  std::vector<std::vector<float>> custom;
  bool first = true;
  for (auto leaf = tree.cbeginLeaf(); leaf; ++leaf) {
    checkLeaf(*leaf, file);
    const vdbp::AttributeSet::Descriptor& d = leaf->attributeSet().descriptor();
    // Every leaf of a PointDataGrid shares one descriptor: positions and names are the first
    // leaf's.
    const std::size_t pPos = d.find("P");
    if (pPos == vdbp::AttributeSet::INVALID_POS) {
      throw std::runtime_error(where(file) + ": the points have no attribute P");
    }
    if (!leaf->constAttributeArray(pPos).hasValueType<openvdb::Vec3f>()) {
      throw std::runtime_error(where(file) + ": P is of type " + d.valueType(pPos) +
                               " (expected vec3s)");
    }
    auto find = [&](const char* name, auto typed) {
      const std::size_t pos = d.find(name);
      using T = decltype(typed);
      if (pos == vdbp::AttributeSet::INVALID_POS) return pos;
      return leaf->constAttributeArray(pos).template hasValueType<T>()
                 ? pos
                 : vdbp::AttributeSet::INVALID_POS;
    };
    const std::size_t vPos = find("v", openvdb::Vec3f());
    const std::size_t idPos = find("id", std::int64_t());
    const std::size_t id32Pos = find("id", std::int32_t());
    const std::size_t agePos = find("age", float()), lifePos = find("life", float()),
                      massPos = find("mass", float());
    // Every other attribute of a type a frame holds, in the file's order: a float, an int32 (a
    // float column of whole numbers) or a vec3s (three columns: vectorColumns()).
    std::vector<std::size_t> customPos;
    std::vector<AttributeKind> customKinds;
    std::vector<std::string> names(d.size());
    for (const auto& [name, pos] : d.map()) names[pos] = name;
    for (std::size_t pos = 0; pos < d.size(); ++pos) {
      if (isStandard(names[pos])) continue;
      const vdbp::AttributeArray& array = leaf->constAttributeArray(pos);
      const bool isFloat = array.hasValueType<float>(), isInt = array.hasValueType<std::int32_t>(),
                 isVector = array.hasValueType<openvdb::Vec3f>();
      if (!isFloat && !isInt && !isVector) continue;
      customPos.push_back(pos);
      customKinds.push_back(isVector ? AttributeKind::Vec3
                            : isInt  ? AttributeKind::Int
                                     : AttributeKind::Float);
    }
    std::size_t customColumns = 0;
    for (AttributeKind k : customKinds) customColumns += k == AttributeKind::Vec3 ? 3 : 1;
    if (first) {
      found.hasVelocity = vPos != vdbp::AttributeSet::INVALID_POS;
      found.hasId =
          idPos != vdbp::AttributeSet::INVALID_POS || id32Pos != vdbp::AttributeSet::INVALID_POS;
      found.hasAge = agePos != vdbp::AttributeSet::INVALID_POS;
      found.hasLife = lifePos != vdbp::AttributeSet::INVALID_POS;
      found.hasMass = massPos != vdbp::AttributeSet::INVALID_POS;
      for (std::size_t a = 0; a < customPos.size(); ++a) {
        if (customKinds[a] != AttributeKind::Vec3) {
          customNames.push_back(names[customPos[a]]);
          continue;
        }
        for (const std::string& column : vectorColumns(names[customPos[a]]))
          customNames.push_back(column);
      }
      custom.resize(customNames.size());
      first = false;
    }

    vdbp::AttributeHandle<openvdb::Vec3f> p(leaf->constAttributeArray(pPos));
    for (auto index = leaf->beginIndexAll(); index; ++index) {
      const openvdb::Coord ijk = index.getCoord();
      const openvdb::Vec3f o = p.get(*index);
      openvdb::Vec3f x;
      if (identity) {
        // (ijk + P) · 1 as OpenVDB computes it, but a coordinate of voxel 0 is P as stored, so
        // that −0.0 stays −0.0.
        for (int c = 0; c < 3; ++c) {
          x[c] = ijk[c] == 0
                     ? o[c]
                     : static_cast<float>(static_cast<double>(ijk[c]) + static_cast<double>(o[c]));
        }
      } else {
        const openvdb::Vec3d w = transform.indexToWorld(ijk.asVec3d() + openvdb::Vec3d(o));
        x = openvdb::Vec3f(static_cast<float>(w[0]), static_cast<float>(w[1]),
                           static_cast<float>(w[2]));
      }
      position.push_back(x);
    }
    const openvdb::Index count = leaf->pointCount();
    auto readAll = [&](std::size_t pos, auto& out, auto fallback) {
      using T = std::decay_t<decltype(fallback)>;
      if (pos == vdbp::AttributeSet::INVALID_POS) {
        out.insert(out.end(), count, fallback);
        return;
      }
      vdbp::AttributeHandle<T> h(leaf->constAttributeArray(pos));
      for (openvdb::Index k = 0; k < count; ++k) out.push_back(h.get(k));
    };
    readAll(vPos, velocity, openvdb::Vec3f(0.0f));
    if (idPos != vdbp::AttributeSet::INVALID_POS) {
      readAll(idPos, id, std::int64_t{0});
    } else if (id32Pos != vdbp::AttributeSet::INVALID_POS) {
      std::vector<std::int32_t> narrow;
      readAll(id32Pos, narrow, std::int32_t{0});
      id.insert(id.end(), narrow.begin(), narrow.end());
    } else {
      // Without an id the rows are numbered in file order.
      for (openvdb::Index k = 0; k < count; ++k) id.push_back(static_cast<std::int64_t>(id.size()));
    }
    readAll(agePos, age, 0.0f);
    readAll(lifePos, life, std::numeric_limits<float>::infinity());
    readAll(massPos, mass, 1.0f);
    if (customColumns != custom.size()) {
      throw std::runtime_error(where(file) + ": leaves with different attributes");
    }
    std::size_t column = 0;
    for (std::size_t a = 0; a < customPos.size(); ++a) {
      if (customKinds[a] == AttributeKind::Float) {
        readAll(customPos[a], custom[column++], 0.0f);
      } else if (customKinds[a] == AttributeKind::Int) {
        std::vector<std::int32_t> values;
        readAll(customPos[a], values, std::int32_t{0});
        for (std::int32_t v : values) custom[column].push_back(static_cast<float>(v));
        ++column;
      } else {
        std::vector<openvdb::Vec3f> values;
        readAll(customPos[a], values, openvdb::Vec3f(0.0f));
        for (int c = 0; c < 3; ++c, ++column) {
          for (const openvdb::Vec3f& v : values) custom[column].push_back(v[c]);
        }
      }
    }
    if (position.size() != id.size()) {
      throw std::runtime_error(where(file) + ": a leaf's offsets do not match its attributes");
    }
  }

  // Rows in id order (ids are unique in a tickfx cache; equal ids keep the file's order).
  const std::size_t n = position.size();
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), std::size_t{0});
  if (found.hasId) {
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      return static_cast<std::uint64_t>(id[a]) < static_cast<std::uint64_t>(id[b]);
    });
  }
  FrameData frame;
  frame.resize(n, customNames);
  for (std::size_t r = 0; r < n; ++r) {
    const std::size_t i = order[r];
    const auto row = static_cast<Eigen::Index>(r);
    for (int c = 0; c < 3; ++c) {
      frame.position[c][row] = position[i][c];
      frame.velocity[c][row] = velocity[i][c];
    }
    frame.id[r] = static_cast<std::uint64_t>(id[i]);
    frame.age[row] = age[i];
    frame.life[row] = life[i];
    frame.mass[row] = mass[i];
    for (std::size_t a = 0; a < custom.size(); ++a) frame.attributes[a][row] = custom[a][i];
  }

  VdbCacheMetadata& meta = found.metadata;
  meta.effectHash = metaValue<std::string>(*grid, kMetaEffectHash).value_or("");
  meta.seed = static_cast<std::uint64_t>(metaValue<std::int64_t>(*grid, kMetaSeed).value_or(0));
  meta.stepRateHz = metaValue<std::int64_t>(*grid, kMetaStepRate).value_or(0);
  meta.integrator = metaValue<std::string>(*grid, kMetaIntegrator).value_or("");
  meta.tickfxVersion = metaValue<std::string>(*grid, kMetaVersion).value_or("");
  frame.frame = metaValue<std::int64_t>(*grid, kMetaFrame).value_or(0);
  frame.timeSeconds = metaValue<double>(*grid, kMetaTime).value_or(0.0);
  if (contents != nullptr) *contents = found;
  return frame;
}

}  // namespace tickfx::io
