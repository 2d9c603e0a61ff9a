// The order in which an advection step visits a block of rows: leaf by leaf of the field's grid.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "fields/ForceSet.h"
#include "particles/ParallelFor.h"

namespace tickfx {

/// A permutation of one block of rows, sorted by the grid block (an OpenVDB leaf node) that each
/// row's position samples (ForceSet::sampleBlocks), rows of one grid block in increasing order: a
/// stable counting sort, so the order is a function of the positions alone. Visiting rows in this
/// order lets consecutive samples share a leaf's memory and lookup when the pool's rows are
/// scattered in space; it changes no value (the pool's rows stay where they are).
///
/// One order covers a block of rows (blockRows()): large enough that each leaf a block touches
/// serves many of its rows (a leaf is read into cache once per block and stage, not once per
/// row), small enough that the block's rows, which a visit gathers and scatters, stay in the
/// last-level cache. Blocks are a function of the row count alone and each is one task, so every
/// row is written by its own task. Rebuilt every tick (build() costs about one sample's index
/// arithmetic per row), so it is never stale after particles move, are born or die. Not
/// thread-safe: one instance per thread.
class LeafOrder {
 public:
  /// Rows one order covers at most.
  static constexpr std::size_t kMaxRows = 65536;
  /// The rows of each block over `rows` rows: 1/16 of them (parallel slack), from
  /// kParallelBlockRows to kMaxRows.
  static std::size_t blockRows(std::size_t rows) {
    return rows / 16 < kParallelBlockRows ? kParallelBlockRows
                                          : (rows / 16 > kMaxRows ? kMaxRows : rows / 16);
  }
  /// Grid blocks are merged (coordinates shifted down) until a block's rows span at most this
  /// many buckets, so the counting sort's table stays in L1.
  static constexpr std::int64_t kMaxBuckets = 2048;
  /// Rows already in order (at most one change of grid block per kCoherentRun rows on average)
  /// are best visited as they are: their samples share leaves already.
  static constexpr std::size_t kCoherentRun = 32;

  /// Orders rows `rows` (at most kMaxRows) of `position`. False, with no order, when there is
  /// nothing to gain: the forces have no grid blocks, the rows are already coherent, or a row
  /// index does not fit 32 bits. Then the rows are best visited in their order.
  bool build(const ForceSet& forces, const Vec3Column& position, RowRange rows);

  /// The pool rows in visiting order (after build() returned true): size() of them.
  const std::uint32_t* rows() const { return order_.data(); }
  std::size_t size() const { return order_.size(); }

 private:
  // The counting sort of coords_ into order_, buckets of 2^shift grid blocks a side.
  void sortByBucket(RowRange rows);

  std::vector<BlockCoord> coords_;
  std::vector<std::uint32_t> keys_, counts_, order_;
};

}  // namespace tickfx
