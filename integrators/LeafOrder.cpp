#include "integrators/LeafOrder.h"

#include <algorithm>
#include <limits>
#include <utility>

namespace tickfx {

namespace {

bool isPlaced(const BlockCoord& b) { return b.x != BlockCoord::kNowhere; }

bool sameBlock(const BlockCoord& a, const BlockCoord& b) {
  return a.x == b.x && a.y == b.y && a.z == b.z;
}

// How many times consecutive rows change grid block.
std::size_t blockChanges(const std::vector<BlockCoord>& coords) {
  std::size_t changes = 0;
  for (std::size_t j = 1; j < coords.size(); ++j) {
    changes += static_cast<std::size_t>(!sameBlock(coords[j], coords[j - 1]));
  }
  return changes;
}

// The box of the placed coordinates, in 64 bits so that shifted extents cannot overflow.
struct BlockBox {
  std::int64_t lo[3] = {0, 0, 0};
  std::int64_t hi[3] = {0, 0, 0};
};

BlockBox blockBoxOf(const std::vector<BlockCoord>& coords) {
  BlockBox box;
  bool any = false;
  for (const BlockCoord& b : coords) {
    if (!isPlaced(b)) continue;
    const std::int64_t v[3] = {b.x, b.y, b.z};
    for (int c = 0; c < 3; ++c) {
      box.lo[c] = any ? std::min(box.lo[c], v[c]) : v[c];
      box.hi[c] = any ? std::max(box.hi[c], v[c]) : v[c];
    }
    any = true;
  }
  return box;
}

// Buckets of 2^shift blocks a side over `box`: the smallest shift that needs at most `most`.
struct BucketGrid {
  int shift = 0;
  std::int64_t extent[3] = {1, 1, 1};
  std::int64_t count() const { return extent[0] * extent[1] * extent[2]; }
};

BucketGrid bucketsFor(const BlockBox& box, std::int64_t most) {
  for (BucketGrid b;; ++b.shift) {
    bool fits = true;
    for (int c = 0; c < 3; ++c) {
      b.extent[c] = (box.hi[c] >> b.shift) - (box.lo[c] >> b.shift) + 1;
      fits = fits && b.extent[c] <= most;
    }
    // Each extent at most `most` first, so that the product cannot overflow.
    if (fits && b.count() <= most) return b;
  }
}

}  // namespace

bool LeafOrder::build(const ForceSet& forces, const Vec3Column& position, RowRange rows) {
  TICKFX_ASSERT(rows.begin <= rows.end && rows.end - rows.begin <= kMaxRows,
                "a leaf order over more rows than a block");
  order_.clear();
  const std::size_t n = rows.end - rows.begin;
  if (n == 0 || rows.end > std::numeric_limits<std::uint32_t>::max()) return false;
  coords_.resize(n);
  if (!forces.sampleBlocks(Vec3View::of(position), rows, coords_.data())) return false;
  if (blockChanges(coords_) * kCoherentRun <= n) return false;
  sortByBucket(rows);
  return true;
}

void LeafOrder::sortByBucket(RowRange rows) {
  const BlockBox box = blockBoxOf(coords_);
  const BucketGrid buckets = bucketsFor(box, kMaxBuckets);
  const auto nowhere = static_cast<std::uint32_t>(buckets.count());  // the last bucket
  const std::size_t n = coords_.size();
  keys_.resize(n);
  counts_.assign(static_cast<std::size_t>(nowhere) + 1, 0);
  const int s = buckets.shift;
  for (std::size_t j = 0; j < n; ++j) {
    const BlockCoord& b = coords_[j];
    std::uint32_t key = nowhere;
    if (isPlaced(b)) {
      const std::int64_t x = (std::int64_t{b.x} >> s) - (box.lo[0] >> s);
      const std::int64_t y = (std::int64_t{b.y} >> s) - (box.lo[1] >> s);
      const std::int64_t z = (std::int64_t{b.z} >> s) - (box.lo[2] >> s);
      key = static_cast<std::uint32_t>((x * buckets.extent[1] + y) * buckets.extent[2] + z);
    }
    keys_[j] = key;
    ++counts_[key];
  }
  std::uint32_t next = 0;
  for (std::uint32_t& c : counts_) next += std::exchange(c, next);
  order_.resize(n);
  for (std::size_t j = 0; j < n; ++j) {
    order_[counts_[keys_[j]]++] = static_cast<std::uint32_t>(rows.begin + j);
  }
}

}  // namespace tickfx
