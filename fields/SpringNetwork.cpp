#include "fields/SpringNetwork.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "particles/Assert.h"
#include "particles/ParallelFor.h"

namespace tickfx {
namespace {

constexpr std::uint32_t kMissing = std::numeric_limits<std::uint32_t>::max();

// Rows are in id order (spawns append increasing ids, deaths compact stably). Until something
// dies, a particle's row is its id minus the first id: try that before a binary search, which
// otherwise cost most of a cloth's tick.
std::uint32_t rowOf(const RowColumn<std::uint64_t>& ids, std::size_t size, std::uint64_t id) {
  if (size > 0 && id >= ids[0]) {
    const std::uint64_t guess = id - ids[0];
    if (guess < size && ids[guess] == id) return static_cast<std::uint32_t>(guess);
  }
  const auto end = ids.begin() + static_cast<std::ptrdiff_t>(size);
  const auto it = std::lower_bound(ids.begin(), end, id);
  return (it != end && *it == id) ? static_cast<std::uint32_t>(it - ids.begin()) : kMissing;
}

// Whether a breakable spring between rows ra and rb is stretched past its ratio.
bool stretchedPastItsRatio(const Spring& spring, const Vec3Column& p, std::uint32_t ra,
                           std::uint32_t rb) {
  if (!(spring.breakRatio > 0.0f)) return false;
  const float dx = p.x[rb] - p.x[ra], dy = p.y[rb] - p.y[ra], dz = p.z[rb] - p.z[ra];
  const float length = std::sqrt(dx * dx + dy * dy + dz * dz);
  return length > spring.breakRatio * spring.restLength;
}

}  // namespace

void SpringNetwork::beginTick(const ParticlePool& pool, std::int64_t /*tick*/) {
  if (!tablesStillHold(pool)) rebuild(pool);
}

// The tables are a function of the rows' ids, the ids born so far (an end not born yet) and the
// positions (breaks). Rows that did not move, no end born or dying, and no spring stretched past
// its ratio give the tables of the tick before: most ticks of a cloth. The break test reads only
// (parallel blocks, a flag); any break leaves the rebuild to do it in spring order.
bool SpringNetwork::tablesStillHold(const ParticlePool& pool) const {
  if (!built_ || pool.rowsVersion() != builtRowsVersion_) return false;
  if (pendingEnds_ > 0 && pool.nextId() != builtNextId_) return false;
  if (!breakable_) return true;
  const Vec3Column& p = pool.position();
  RelaxedFlag broke;
  parallelForRows(ends_.size(), [&](std::size_t begin, std::size_t end) {
    for (std::size_t k = begin; k < end; ++k) {
      const Ends& e = ends_[k];
      if (stretchedPastItsRatio(springs_[e.spring], p, e.a, e.b)) {
        broke.raise();
        return;
      }
    }
  });
  return !broke.get();
}

void SpringNetwork::rebuild(const ParticlePool& pool) {
  const std::size_t n = pool.size();
  const Vec3Column& p = pool.position();
  // Resolve ends, drop springs with a dead end, break the overstretched: all from the state at
  // the start of the tick, in spring order, so the surviving list is the same on every run.
  ends_.clear();
  ends_.reserve(springs_.size());
  std::size_t kept = 0;
  pendingEnds_ = 0;
  breakable_ = false;
  for (std::size_t s = 0; s < springs_.size(); ++s) {
    const Spring& spring = springs_[s];
    const std::uint32_t ra = rowOf(pool.id(), n, spring.a);
    const std::uint32_t rb = rowOf(pool.id(), n, spring.b);
    if (ra == kMissing || rb == kMissing) {
      // An end not born yet keeps the spring; an end that died removes it.
      const bool died = (ra == kMissing && spring.a < pool.nextId()) ||
                        (rb == kMissing && spring.b < pool.nextId());
      if (!died) {
        breakable_ = breakable_ || spring.breakRatio > 0.0f;
        springs_[kept++] = spring;
        ++pendingEnds_;
      }
      continue;
    }
    if (stretchedPastItsRatio(spring, p, ra, rb)) {
      ++broken_;
      continue;
    }
    breakable_ = breakable_ || spring.breakRatio > 0.0f;
    TICKFX_ASSERT(ra < n && rb < n, "a spring end past the pool's rows");
    ends_.push_back(Ends{ra, rb, static_cast<std::uint32_t>(kept)});
    springs_[kept++] = spring;
  }
  springs_.resize(kept);

  // Each row's links, in spring order (a counting sort keeps that order within a row).
  first_.assign(n + 1, 0);
  for (const Ends& e : ends_) {
    ++first_[e.a + 1];
    ++first_[e.b + 1];
  }
  for (std::size_t r = 0; r < n; ++r) first_[r + 1] += first_[r];
  TICKFX_ASSERT(first_[n] == 2 * ends_.size(), "a spring link table that lost an end");
  links_.resize(first_[n]);
  std::vector<std::uint32_t> fill(first_.begin(), first_.end() - 1);
  for (const Ends& e : ends_) {
    links_[fill[e.a]++] = Link{e.b, e.spring};
    links_[fill[e.b]++] = Link{e.a, e.spring};
  }
  built_ = true;
  builtRowsVersion_ = pool.rowsVersion();
  builtNextId_ = pool.nextId();
}

void SpringNetwork::accumulate(const ForceInput& in, RowRange rows, Vec3Rows& acc) const {
  const Vec3View& p = in.position;
  const Vec3View& v = in.velocity;
  const FloatColumn& mass = in.pool.mass();
  for (std::size_t i = rows.begin; i < rows.end; ++i) {
    if (i + 1 >= first_.size()) break;  // rows spawned after beginTick (none within a tick)
    float fx = 0.0f, fy = 0.0f, fz = 0.0f;
    const Eigen::Vector3f pi = p.at(i), vi = v.at(i);
    for (std::uint32_t l = first_[i]; l < first_[i + 1]; ++l) {
      const Spring& s = springs_[links_[l].spring];
      const std::size_t j = links_[l].other;
      TICKFX_ASSERT(j + 1 < first_.size(), "a spring link past the rows of its table");
      const Eigen::Vector3f pj = p.at(j), vj = v.at(j);
      const float dx = pj.x() - pi.x(), dy = pj.y() - pi.y(), dz = pj.z() - pi.z();
      const float length = std::sqrt(dx * dx + dy * dy + dz * dz);
      if (!(length > 0.0f)) continue;  // coincident ends: no direction, no force
      const float ux = dx / length, uy = dy / length, uz = dz / length;
      const float closing =
          (vj.x() - vi.x()) * ux + (vj.y() - vi.y()) * uy + (vj.z() - vi.z()) * uz;
      const float f = s.stiffness * (length - s.restLength) + s.damping * closing;
      fx += f * ux;
      fy += f * uy;
      fz += f * uz;
    }
    const float w = inverseMassOf(mass[static_cast<Eigen::Index>(i)]);
    const auto k = static_cast<Eigen::Index>(i - rows.begin);
    acc.x[k] += fx * w;
    acc.y[k] += fy * w;
    acc.z[k] += fz * w;
  }
}

}  // namespace tickfx
