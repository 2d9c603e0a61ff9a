#include "fields/ForceSet.h"

#include <algorithm>

namespace tickfx {

ForceModule& ForceSet::add(std::unique_ptr<ForceModule> module) {
  modules_.push_back(std::move(module));
  return *modules_.back();
}

bool ForceSet::isLocal() const {
  return std::all_of(modules_.begin(), modules_.end(), [](const auto& m) { return m->isLocal(); });
}

void ForceSet::beginTick(const ParticlePool& pool, std::int64_t tick) {
  for (auto& m : modules_) m->beginTick(pool, tick);
  const auto n = static_cast<Eigen::Index>(pool.size());
  anyPinned_ = n > 0 && (pool.inverseMass().head(n) == 0.0f).any();
}

void ForceSet::evaluate(const ForceInput& in, RowRange rows, Vec3Rows& acceleration) const {
  // Only a leading run of uniform modules is folded: (0 + g) + w is then the very sum each row
  // would have formed, while folding a uniform module after a per-row one would reorder it.
  Eigen::Vector3f uniform = Eigen::Vector3f::Zero();
  std::size_t next = 0;
  for (Eigen::Vector3f a; next < modules_.size() && modules_[next]->uniformAcceleration(in, a);
       ++next) {
    uniform.x() += a.x();
    uniform.y() += a.y();
    uniform.z() += a.z();
  }
  acceleration.x.setConstant(uniform.x());
  acceleration.y.setConstant(uniform.y());
  acceleration.z.setConstant(uniform.z());
  for (; next < modules_.size(); ++next) modules_[next]->accumulate(in, rows, acceleration);
  if (anyPinned_) {
    // A pinned particle (infinite mass) does not move: no force accelerates it, gravity included.
    const auto pinned = in.pool.inverseMass().segment(rows.offset(), rows.count()) == 0.0f;
    acceleration.x = pinned.select(0.0f, acceleration.x);
    acceleration.y = pinned.select(0.0f, acceleration.y);
    acceleration.z = pinned.select(0.0f, acceleration.z);
  }
}

}  // namespace tickfx
