#include "fields/ColliderSet.h"

#include <cstring>
#include <stdexcept>

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

void ColliderSet::beginTick(ParticlePool& pool, std::int64_t tick, std::int64_t stepRateHz,
                            bool history) {
  paths_.clear();
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
  t.counts = nullptr;
  if (!countColumn_.empty()) {
    t.counts = pool.attribute(pool.findAttribute(countColumn_)).data();
    blockContacts_.resize(std::max(blockContacts_.size(), t.blocks));
    for (std::size_t k = 0; k < t.blocks; ++k) blockContacts_[k].clear();
  }
  // The hit columns, where the pool has them.
  t.hits.fill(nullptr);
  if (pool.findAttribute(kHitColumns[0]) != ParticlePool::npos) {
    for (std::size_t k = 0; k < kHitColumns.size(); ++k)
      t.hits[k] = pool.attribute(pool.findAttribute(kHitColumns[k])).data();
  }
}

void ColliderSet::collideRows(ParticlePool& pool, std::size_t begin, std::size_t end,
                              const std::array<const float*, 3>& given) {
  if (colliders_.empty() || begin >= end) return;
  TICKFX_ASSERT(begin % kParallelBlockRows == 0 && end - begin <= kParallelBlockRows,
                "collideRows() takes whole blocks of kParallelBlockRows rows");
  TICKFX_ASSERT((given[0] != nullptr && !tick_.history) || pool.keepsPrevious(),
                "paths start at the pool's previous positions, which it does not keep");
  const TickState& t = tick_;
  const float dt = t.dt;
  Vec3Column& pos = pool.position();
  Vec3Column& vel = pool.velocity();
  Vec3Column& prev = pool.previousPosition();
  // Only a kill flags a row: a mutable dead() would have the tick's end scan every row for none.
  std::uint8_t* const dead = t.kills ? pool.dead().data() : nullptr;
  const std::uint64_t* ids = pool.id().data();
  std::vector<CollisionPath>& found = blockPaths_[begin / kParallelBlockRows];
  // Which rows may touch a collider: a screen over the block's columns first.
  thread_local std::vector<std::uint8_t> flags;
  flags.assign(end - begin, 0);
  const float* starts[3];
  for (int c = 0; c < 3; ++c)
    starts[c] = given[0] != nullptr ? given[static_cast<std::size_t>(c)] : prev[c].data() + begin;
  const float* const ends[3] = {pos.x.data() + begin, pos.y.data() + begin, pos.z.data() + begin};
  for (const auto& c : colliders_) c->screen(starts, ends, end - begin, flags.data());
  // Most rows are screened out: skipped eight at a time, through a pointer read once (the
  // thread_local vector would be looked up again every row).
  const std::uint8_t* const flagged = flags.data();
  const std::size_t count = end - begin;
  for (std::size_t k = 0; k < count; ++k) {
    if ((k & 7) == 0 && k + 8 <= count) {
      std::uint64_t eight = 0;
      std::memcpy(&eight, flagged + k, sizeof eight);
      if (eight == 0) {
        k += 7;
        continue;
      }
    }
    if (flagged[k] == 0) continue;
    const std::size_t i = begin + k;
    const auto row = static_cast<Eigen::Index>(i);
    Eigen::Vector3f a(starts[0][k], starts[1][k], starts[2][k]);
    Eigen::Vector3f b(pos.x[row], pos.y[row], pos.z[row]);
    Eigen::Vector3f v(vel.x[row], vel.y[row], vel.z[row]);
    CollisionPath path;
    float from = 0.0f;
    int recorded = 0;
    Contact lastHit;
    Eigen::Vector3f hitVelocity = Eigen::Vector3f::Zero();
    std::vector<ContactRecord>* records =
        t.counts != nullptr ? &blockContacts_[begin / kParallelBlockRows] : nullptr;
    while (path.contacts < kMaxContactsPerTick) {
      Contact best, contact;
      const Collider* hit = nullptr;
      for (const auto& c : colliders_) {
        if (c->firstContact(a, from, b, contact) &&
            (hit == nullptr || contact.fraction < best.fraction)) {
          best = contact;
          hit = c.get();
        }
      }
      if (hit == nullptr) break;
      if (path.contacts == 0) path.start = a;
      path.fraction[path.contacts] = best.fraction;
      path.point[path.contacts] = best.point;
      ++path.contacts;
      if (records != nullptr) {
        records->push_back(ContactRecord{
            static_cast<std::uint32_t>(i),
            static_cast<std::uint32_t>(t.counts[i]) + static_cast<std::uint32_t>(path.contacts - 1),
            best.point, best.normal, v});
      }
      if (t.hits[0] != nullptr && hit->settings().recordHits) {
        ++recorded;
        lastHit = best;
        hitVelocity = v;
      }
      v = hit->respond(best, v);
      a = best.point;
      from = best.fraction;
      if (hit->settings().response == ColliderResponse::Kill) {
        dead[i] = static_cast<std::uint8_t>(dead[i] | 1);
        b = a;
        break;
      }
      // The rest of the tick at the new velocity; after the last contact allowed, carried
      // along with the collider.
      b = path.contacts < kMaxContactsPerTick ? Eigen::Vector3f(a + v * ((1.0f - from) * dt))
                                              : hit->carried(best);
    }
    if (path.contacts == 0) continue;
    if (t.counts != nullptr) t.counts[i] += static_cast<float>(path.contacts);
    for (int c = 0; c < 3; ++c) {
      pos[c][row] = b[c];
      vel[c][row] = v[c];
      if (t.history) prev[c][row] = b[c] - v[c] * dt;
    }
    if (recorded > 0) {
      const float values[kHitColumns.size()] = {t.hits[0][i] + static_cast<float>(recorded),
                                                t.start + lastHit.fraction * dt,
                                                lastHit.point.x(),
                                                lastHit.point.y(),
                                                lastHit.point.z(),
                                                lastHit.normal.x(),
                                                lastHit.normal.y(),
                                                lastHit.normal.z(),
                                                hitVelocity.x(),
                                                hitVelocity.y(),
                                                hitVelocity.z()};
      for (std::size_t h = 0; h < kHitColumns.size(); ++h) t.hits[h][i] = values[h];
    }
    path.id = ids[i];
    found.push_back(path);
  }
}

void ColliderSet::endTick() {
  if (colliders_.empty()) return;
  for (std::size_t k = 0; k < tick_.blocks; ++k) {
    for (const CollisionPath& p : blockPaths_[k]) {
      contacts_ += static_cast<std::uint64_t>(p.contacts);
      paths_.push_back(p);
    }
  }
}

}  // namespace tickfx
