// Where a frame's points lie in a VDB points grid of voxel size 1, as the grid's position codecs
// place them: each coordinate's voxel and its offset in that voxel, rows placed a block at a time,
// each row's leaf in a box of leaves, and the coordinates' bounds, the loops on the widest
// instruction set here. What VdbPointGrouping sorts the points by. Internal to io/ (not
// installed): it includes OpenVDB's headers.
#pragma once

#include <openvdb/points/PointDataGrid.h>

#include <array>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <utility>

#include "io/cache/FrameData.h"

namespace tickfx::io {

using PlacementLeaf = openvdb::points::PointDataTree::LeafNodeType;

// Points whose coordinates are within this bound sit in their nearest voxel; beyond it (or not
// finite) in voxel 0 of that axis. Far inside the 32-bit voxel indices, with room for a tree's
// nodes around them.
inline constexpr double kLargestIndex = 1073741824.0;  // 2³⁰

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

[[gnu::always_inline]] inline std::pair<openvdb::Int32, float> placeExactly(float x) {
  if (std::isfinite(x) && std::abs(x) < static_cast<float>(kLargestIndex)) {
    const auto [n, offset] = nearestVoxel(x);
    const float back = static_cast<float>(n) + offset;
    if (std::bit_cast<std::uint32_t>(back) == std::bit_cast<std::uint32_t>(x)) return {n, offset};
  }
  return {0, x};
}

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
      const auto [index, o] = Quantised ? placeQuantised(x) : placeExactly(x);
      voxel[c] = index;
      if (offset != nullptr) (*offset)[c] = o;
    }
    return voxel;
  }
};

// The bits of a voxel index that make its leaf's origin.
inline constexpr auto kLeafMask = ~static_cast<openvdb::Int32>(PlacementLeaf::DIM - 1);

// Rows placed kPlacedRows at a time by placeRows(): each axis's voxel indices and offsets.
inline constexpr std::size_t kPlacedRows = 512;
struct PlacedRows {
  std::array<std::array<std::int32_t, kPlacedRows>, 3> index;
  std::array<std::array<float, kPlacedRows>, 3> offset;

  openvdb::Coord voxel(std::size_t k) const { return {index[0][k], index[1][k], index[2][k]}; }
};

// A box of leaves: its first and last leaf origins, and its extent in leaves on each axis.
struct LeafBox {
  std::array<std::int32_t, 3> first{}, last{};
  std::array<std::uint32_t, 3> extent{};
};

/// The bounds', placement and leaf index loops (VdbPointPlacement.cpp) on one instruction set,
/// the widest here, chosen when made (activeIsa()). The same bits on every one.
template <bool Quantised>
struct RowKernels {
  /// Extends [low, high] over the coordinates x[begin, end) below 2³⁰ in magnitude, and returns
  /// whether some other coordinate (beyond, infinite or NaN: placed at 0) is among them.
  using Bounds = bool (*)(const float* x, std::size_t begin, std::size_t end, float& low,
                          float& high);
  /// Places rows [begin, begin + count) (count <= kPlacedRows) as Positions::voxel() does.
  using Place = void (*)(const Positions&, std::size_t begin, std::size_t count, PlacedRows&);
  /// Each of the `count` placed rows' leaf index in the box (x, then y, then z: Coord's order);
  /// false where some row's leaf lies outside it.
  using Index = bool (*)(const PlacedRows&, std::size_t count, const LeafBox&, std::uint32_t* leaf);
  Bounds bounds;
  Place place;
  Index index;

  RowKernels();
};
extern template struct RowKernels<false>;
extern template struct RowKernels<true>;

}  // namespace tickfx::io
