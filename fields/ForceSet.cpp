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
}

void ForceSet::evaluate(const ForceInput& in, RowRange rows, Vec3Column& acceleration) const {
  acceleration.x.segment(rows.offset(), rows.count()).setZero();
  acceleration.y.segment(rows.offset(), rows.count()).setZero();
  acceleration.z.segment(rows.offset(), rows.count()).setZero();
  for (const auto& m : modules_) m->accumulate(in, rows, acceleration);
}

}  // namespace tickfx
