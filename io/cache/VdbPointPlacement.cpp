#include "io/cache/VdbPointPlacement.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>

#include "particles/Isa.h"

namespace tickfx::io {
namespace {

using Leaf = PlacementLeaf;

// Places rows [begin, begin + count) (count <= kPlacedRows) as Positions::voxel() places them,
// the same bits, in loops without branches or calls that the compiler vectorises: the
// coordinates outside the bound (or NaN) are placed as if they were 0, then their results
// replaced (the same rule as placeExactly(), placeQuantised() and nearestVoxel()).
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

}  // namespace

template <bool Quantised>
RowKernels<Quantised>::RowKernels()
    : bounds(&extendBoundsBy<Floats4, Ints4>), place(&placeRows<Quantised>), index(&leafIndices) {
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

template struct RowKernels<false>;
template struct RowKernels<true>;

}  // namespace tickfx::io
