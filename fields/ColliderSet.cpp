#include "fields/ColliderSet.h"

#include <algorithm>
#include <limits>
#include <stdexcept>

#include "fields/ContactRows.h"
#include "particles/Assert.h"
#include "particles/ParallelFor.h"

namespace tickfx {

ColliderSet::ColliderSet() = default;
ColliderSet::~ColliderSet() = default;
ColliderSet::ColliderSet(ColliderSet&&) noexcept = default;
ColliderSet& ColliderSet::operator=(ColliderSet&&) noexcept = default;

Collider& ColliderSet::add(std::unique_ptr<Collider> collider) {
  colliders_.push_back(std::move(collider));
  return *colliders_.back();
}

bool ColliderSet::recordsHits() const {
  for (const auto& c : colliders_)
    if (c->settings().recordHits) return true;
  return false;
}

void ColliderSet::addHitColumns(ParticlePool& pool) const {
  if (!recordsHits()) return;
  for (const char* name : kHitColumns) pool.addAttribute(name, 0.0f);
}

Eigen::Vector3f CollisionPath::at(float alpha, const Eigen::Vector3f& end) const {
  if (alpha <= 0.0f) return start;
  if (alpha >= 1.0f) return end;
  float f0 = 0.0f;
  Eigen::Vector3f p0 = start;
  for (int k = 0; k <= contacts; ++k) {
    const float f1 = k < contacts ? fraction[k] : 1.0f;
    const Eigen::Vector3f& p1 = k < contacts ? point[k] : end;
    if (alpha <= f1) {
      if (!(f1 > f0)) return p1;
      const float w = (alpha - f0) / (f1 - f0);
      return p0 + (p1 - p0) * w;
    }
    f0 = f1;
    p0 = p1;
  }
  return end;
}

void ColliderSet::collide(ParticlePool& pool, std::int64_t tick, std::int64_t stepRateHz,
                          bool history) {
  if (!colliders_.empty() && !pool.keepsPrevious()) {
    // A path starts at the previous position: without the column there is no path to test.
    throw std::invalid_argument(
        "colliders need the pool's previous positions: call ParticlePool::keepPrevious() first");
  }
  beginTick(pool, tick, stepRateHz, history);
  if (!colliders_.empty()) {
    parallelForRows(pool.size(),
                    [&](std::size_t begin, std::size_t end) { collideRows(pool, begin, end); });
  }
  endTick();
}

namespace {

static_assert(kParallelBlockRows == 64 * StartsSpan::kGroupRows,
              "a block's groups of rows are the 64 bits of a StepRows::written mask");

// ColliderSet::startsSpan() of `colliders`: the union of their spans on the first axis (y, x, z)
// where each has one.
StartsSpan spanOf(const std::vector<std::unique_ptr<Collider>>& colliders) {
  for (const int axis : {1, 0, 2}) {
    StartsSpan span{-1, std::numeric_limits<float>::infinity(),
                    -std::numeric_limits<float>::infinity()};
    bool bounded = true;
    for (const auto& c : colliders) {
      float lo = 0.0f, hi = 0.0f;
      if (!c->screenSpan(axis, lo, hi) || !(lo <= hi)) {
        bounded = false;
        break;
      }
      span.lo = std::min(span.lo, lo);
      span.hi = std::max(span.hi, hi);
    }
    if (bounded) {
      span.axis = axis;
      return span;
    }
  }
  return {};
}

}  // namespace

void ColliderSet::beginTick(ParticlePool& pool, std::int64_t tick, std::int64_t stepRateHz,
                            bool history) {
  contacts_ = 0;
  if (colliders_.empty()) return;
  for (auto& c : colliders_) c->beginTick(tick, stepRateHz);
  TickState& t = tick_;
  t.dt = static_cast<float>(1.0 / static_cast<double>(stepRateHz));
  // A contact's time is the tick's start (exact, then rounded to float once) plus its fraction of
  // the step, in float.
  t.start = static_cast<float>(static_cast<double>(tick) / static_cast<double>(stepRateHz));
  t.history = history;
  t.kills = false;
  for (const auto& c : colliders_) t.kills |= c->settings().response == ColliderResponse::Kill;
  t.blocks = (pool.size() + kParallelBlockRows - 1) / kParallelBlockRows;
  blockPaths_.resize(std::max(blockPaths_.size(), t.blocks));
  for (std::size_t k = 0; k < t.blocks; ++k) blockPaths_[k].clear();
  blockContactCounts_.assign(t.blocks, 0);
  t.counts = nullptr;
  if (!countColumn_.empty()) {
    t.counts = pool.attribute(pool.findAttribute(countColumn_)).data();
    blockContacts_.resize(std::max(blockContacts_.size(), t.blocks));
    for (std::size_t k = 0; k < t.blocks; ++k) blockContacts_[k].clear();
  }
  t.span = spanOf(colliders_);
  // The hit columns, where the pool has them.
  t.hits.fill(nullptr);
  if (pool.findAttribute(kHitColumns[0]) != ParticlePool::npos) {
    for (std::size_t k = 0; k < kHitColumns.size(); ++k)
      t.hits[k] = pool.attribute(pool.findAttribute(kHitColumns[k])).data();
  }
}

void ColliderSet::collideRows(ParticlePool& pool, std::size_t begin, std::size_t end,
                              const std::array<const float*, 3>& given, std::uint64_t written) {
  if (colliders_.empty() || begin >= end) return;
  TICKFX_ASSERT(begin % kParallelBlockRows == 0 && end - begin <= kParallelBlockRows,
                "collideRows() takes whole blocks of kParallelBlockRows rows");
  TICKFX_ASSERT((given[0] != nullptr && !tick_.history) || pool.keepsPrevious(),
                "paths start at the pool's previous positions, which it does not keep");
  // A block far from every collider (its contact count and paths are cleared by beginTick()).
  if (written == 0) return;
  const TickState& t = tick_;
  const std::size_t block = begin / kParallelBlockRows;
  Vec3Column& pos = pool.position();
  Vec3Column& vel = pool.velocity();
  Vec3Column& prev = pool.previousPosition();
  collide::RowsJob job;
  job.begin = begin;
  job.count = end - begin;
  for (std::size_t c = 0; c < 3; ++c) {
    const auto axis = static_cast<int>(c);
    job.starts[c] = given[0] != nullptr ? given[c] : prev[axis].data() + begin;
    job.position[c] = pos[axis].data();
    job.velocity[c] = vel[axis].data();
    job.previous[c] = prev[axis].data();
  }
  // Only a kill flags a row: a mutable dead() would have the tick's end scan every row for none.
  job.dead = t.kills ? pool.dead().data() : nullptr;
  job.ids = pool.id().data();
  job.dt = t.dt;
  job.start = t.start;
  job.history = t.history;
  job.hits = t.hits;
  job.counts = t.counts;
  job.found = &blockPaths_[block];
  job.records = t.counts != nullptr ? &blockContacts_[block] : nullptr;
  // Which rows may touch a collider: a screen over the block's columns first.
  thread_local std::vector<std::uint8_t> flags;
  flags.assign(job.count, 0);
  // The groups of rows the step wrote every start of, in runs: the others reach no screen.
  constexpr std::size_t g = StartsSpan::kGroupRows;
  for (std::size_t k = 0; k * g < job.count;) {
    if ((written >> k & 1) == 0) {
      ++k;
      continue;
    }
    const std::size_t first = k;
    while (k * g < job.count && (written >> k & 1) != 0) ++k;
    const std::size_t from = first * g, n = std::min(job.count, k * g) - from;
    const float* const a[3] = {job.starts[0] + from, job.starts[1] + from, job.starts[2] + from};
    const float* const b[3] = {pos.x.data() + begin + from, pos.y.data() + begin + from,
                               pos.z.data() + begin + from};
    for (const auto& c : colliders_) c->screen(a, b, n, flags.data() + from);
  }
  job.flagged = flags.data();
  // A lone collider runs the loop its own way (a shape's test inlined); several, through their
  // virtual calls.
  using Several = collide::VirtualColliders<const std::unique_ptr<Collider>*>;
  blockContactCounts_[block] =
      colliders_.size() == 1
          ? colliders_.front()->contactRows(job)
          : collide::contactRows(job,
                                 Several{colliders_.data(), colliders_.data() + colliders_.size()});
}

void ColliderSet::endTick() {
  if (colliders_.empty()) return;
  for (std::size_t k = 0; k < tick_.blocks; ++k) contacts_ += blockContactCounts_[k];
}

std::vector<CollisionPath> ColliderSet::paths() const {
  std::vector<CollisionPath> all;
  for (const std::vector<CollisionPath>& block : pathBlocks())
    all.insert(all.end(), block.begin(), block.end());
  return all;
}

}  // namespace tickfx
