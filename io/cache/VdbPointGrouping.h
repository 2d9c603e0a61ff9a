// A frame's points grouped into the leaves and voxels of a VDB points grid, in the order the
// leaves' arrays hold them: what writeVdbPointCache makes its tree and stores its arrays from.
// Internal to io/ (not installed): it includes OpenVDB's headers, which VdbPointCache.h keeps out.
#pragma once

#include <openvdb/points/PointDataGrid.h>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "io/cache/FrameData.h"
#include "io/cache/VdbPointsEncoder.h"

namespace tickfx::io {

/// The buckets of consecutive leaves that Grouping::Any sorts one at a time, for leaves whose
/// points start at `starts` (and end at its last entry): first[b] is bucket b's first leaf
/// (first[count()] the number of leaves), of[l] the bucket of leaf l.
struct Buckets {
  std::vector<std::uint32_t> first, of;

  Buckets() = default;
  explicit Buckets(const std::vector<std::size_t>& starts);
  std::size_t count() const { return first.size() - 1; }
};

/// The points in the order the leaves' arrays hold them: the leaves in Coord order (ascending, as
/// Coord's operator< orders them), a leaf's points by voxel, and in row order within a voxel. Each
/// point's values are copied here, point k's at row(k): in that order, or each bucket's in the
/// frame's row order (Grouping::Any).
struct GroupedPoints {
  std::vector<std::size_t> starts;  // each leaf's first point, and the end
  // Each leaf's origin, point count, mask and voxel ends (the encoder's description of the
  // leaves; its sample leaf is the cache's to set).
  PointLeaves leaves;
  // (Large arrays: in a virtual machine, faulting in 4 KiB pages cost more than the copying.)
  LargeArray<openvdb::Vec3f> offset;  // each point's position's offset in its voxel
  LargeArray<std::uint64_t> id;
  // A column of float values (not the frame's FloatColumn): `width` floats a row. Width 0: a
  // column of one float a row whose rows all hold the same bits (as a frame's lives or masses
  // often do) holds that value alone, at every row's place: nothing to move.
  struct Column {
    LargeArray<float> values;
    std::size_t width = 1;
  };
  // The velocity's x, y, z in rows of three (scattered as one stream rather than three, and read
  // whole), then the ages, lives and masses, then the frame's attribute columns, one float a row
  // (kStandardFloatColumns); made by the grouping with the values' widths.
  std::vector<Column> columns;
  // Where set (Grouping::Any), `offset`, `id` and `columns` hold each bucket's rows in the
  // frame's row order, not in the leaves' order: point k's values are at row source[k] (in its
  // own bucket). The store gathers each leaf's values through it straight into the file's bytes,
  // the bucket's rows in cache: putting each column in order first took a copy and a scatter of
  // it, and the store a copy more. Null: point k's values are at row k.
  LargeArray<std::uint32_t> source;
  Buckets buckets;

  explicit GroupedPoints(std::size_t n)
      : offset(allocateLargeArray<openvdb::Vec3f>(n)), id(allocateLargeArray<std::uint64_t>(n)) {}
  // The row of `offset`, `id` and `columns` that holds point k's values.
  std::size_t row(std::size_t k) const { return source ? source[k] : k; }
  // The points of leaf l: [first, second).
  std::pair<std::size_t, std::size_t> leafPoints(std::size_t l) const {
    return {starts[l], starts[l + 1]};
  }
  // The points of bucket b: [first, second).
  std::pair<std::size_t, std::size_t> bucketPoints(std::size_t b) const {
    return {starts[buckets.first[b]], starts[buckets.first[b + 1]]};
  }
};

/// GroupedPoints::columns' first ones, from the frame's standard columns: the velocity's x, y, z
/// in rows of three, then the ages, lives and masses one float a row. The frame's attribute
/// columns follow, one float a row.
inline constexpr std::size_t kVelocityColumn = 0;
inline constexpr std::size_t kAgeColumn = 1;
inline constexpr std::size_t kLifeColumn = 2;
inline constexpr std::size_t kMassColumn = 3;
inline constexpr std::size_t kStandardFloatColumns = 4;

/// Which way the points are grouped: only tests ask for the general way.
enum class Grouping {
  /// A counting sort of the rows by bucket of leaves, then by leaf and voxel within each bucket,
  /// where the leaves' bounding box is small enough to count them in a table (any effect of sane
  /// size); the sort below otherwise. Its `id` and `columns` are read through `source`.
  Any,
  /// Every point's (leaf, voxel, row) sorted: the general way.
  Sorted,
};

/// The frame's points grouped into leaves and voxels, each point placed as the grid's position
/// codec places it: the 16-bit fixed-point one when `Quantised`, else exactly (its voxel and
/// offset add up to its coordinate's bits; a coordinate for which they cannot goes whole into
/// voxel 0). The order, and so the bytes of the file, depends neither on `grouping` nor on the
/// thread count.
template <bool Quantised>
GroupedPoints groupPoints(const FrameData& frame, Grouping grouping);
extern template GroupedPoints groupPoints<false>(const FrameData&, Grouping);
extern template GroupedPoints groupPoints<true>(const FrameData&, Grouping);

}  // namespace tickfx::io
