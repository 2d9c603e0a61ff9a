#include "fields/ForceSet.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "particles/ParallelFor.h"

namespace tickfx {

namespace {

// A pinned particle (infinite mass) does not move: no force accelerates it, gravity included, and
// no flow carries it.
void holdPinned(const ForceInput& in, RowRange rows, Vec3Rows& value) {
  const auto pinned = in.pool.mass().segment(rows.offset(), rows.count()).isInf();
  value.x = pinned.select(0.0f, value.x);
  value.y = pinned.select(0.0f, value.y);
  value.z = pinned.select(0.0f, value.z);
}

// holdPinned() for values gathered from pool rows rows[j]: the same test (an infinite mass),
// row for row.
void holdPinnedGathered(const FloatColumn& mass, const std::uint32_t* rows, Vec3Rows& value) {
  for (Eigen::Index j = 0; j < value.x.size(); ++j) {
    if (std::isinf(mass[rows[j]])) value.x[j] = value.y[j] = value.z[j] = 0.0f;
  }
}

}  // namespace

ForceModule& ForceSet::add(std::unique_ptr<ForceModule> module) {
  for (const auto& m : modules_) {
    if (m->prescribesVelocity() != module->prescribesVelocity()) {
      const ForceModule& advect = m->prescribesVelocity() ? *m : *module;
      const ForceModule& force = m->prescribesVelocity() ? *module : *m;
      throw std::invalid_argument(
          std::string(advect.typeName()) + " in advect mode sets the velocity, so the " +
          std::string(force.typeName()) +
          " force would be ignored: an advected effect cannot have acceleration forces (use "
          "mode \"drag\" to pull particles toward the field instead)");
    }
  }
  advects_ = module->prescribesVelocity();
  gathers_ = gathers_ && module->velocityFromPositionsOnly();
  modules_.push_back(std::move(module));
  return *modules_.back();
}

bool ForceSet::isLocal() const {
  return std::all_of(modules_.begin(), modules_.end(), [](const auto& m) { return m->isLocal(); });
}

bool ForceSet::arithmeticOnly() const {
  return std::all_of(modules_.begin(), modules_.end(),
                     [](const auto& m) { return m->arithmeticOnly(); });
}

bool ForceSet::interleavesTicks() const {
  return std::all_of(modules_.begin(), modules_.end(),
                     [](const auto& m) { return m->interleavesTicks(); });
}

void ForceSet::beginTick(const ParticlePool& pool, std::int64_t tick) {
  for (auto& m : modules_) m->beginTick(pool, tick);
  // A scan only when a spawn or a host's write may have pinned a particle since the last one
  // found none (ParticlePool::mayHavePinned).
  anyPinned_ = pool.anyPinned();
}

std::size_t ForceSet::uniformPrefix(const ForceInput& in, Eigen::Vector3f& uniform) const {
  // Only a leading run of uniform modules is folded: (0 + g) + w is then the very sum each row
  // would have formed, while folding a uniform module after a per-row one would reorder it.
  uniform = Eigen::Vector3f::Zero();
  std::size_t next = 0;
  for (Eigen::Vector3f a; next < modules_.size() && modules_[next]->uniformAcceleration(in, a);
       ++next) {
    uniform.x() += a.x();
    uniform.y() += a.y();
    uniform.z() += a.z();
  }
  return next;
}

std::optional<ForceSet::UniformAndDrag> ForceSet::uniformAndDrag(const ForceInput& in) const {
  if (anyPinned_ || advects_) return std::nullopt;
  UniformAndDrag form;
  const std::size_t next = uniformPrefix(in, form.uniform);
  if (next == modules_.size()) return form;
  if (next + 1 == modules_.size() && modules_[next]->linearDrag(form.k, form.air)) {
    form.drag = true;
    return form;
  }
  return std::nullopt;
}

void ForceSet::evaluate(const ForceInput& in, RowRange rows, Vec3Rows& acceleration) const {
  Eigen::Vector3f uniform;
  std::size_t next = uniformPrefix(in, uniform);
  acceleration.x.setConstant(uniform.x());
  acceleration.y.setConstant(uniform.y());
  acceleration.z.setConstant(uniform.z());
  for (; next < modules_.size(); ++next) modules_[next]->accumulate(in, rows, acceleration);
  if (anyPinned_) holdPinned(in, rows, acceleration);
}

void ForceSet::evaluateVelocity(const ForceInput& in, RowRange rows, Vec3Rows& velocity) const {
  velocity.x.setZero();
  velocity.y.setZero();
  velocity.z.setZero();
  for (const auto& m : modules_) m->accumulateVelocity(in, rows, velocity);
  if (anyPinned_) holdPinned(in, rows, velocity);
}

void ForceSet::evaluateVelocityGathered(const ParticlePool& pool, const Vec3View& position,
                                        const std::uint32_t* rows, TickInstant at,
                                        Vec3Rows& velocity) const {
  TICKFX_ASSERT(gathersVelocity(), "gathered positions for a module that reads more than them");
  velocity.x.setZero();
  velocity.y.setZero();
  velocity.z.setZero();
  // The modules read the positions alone: the velocity view is never read.
  const ForceInput in{pool, position, position, at};
  const RowRange elements{0, static_cast<std::size_t>(velocity.x.size())};
  for (const auto& m : modules_) m->accumulateVelocity(in, elements, velocity);
  if (anyPinned_) holdPinnedGathered(pool.mass(), rows, velocity);
}

bool ForceSet::sampleBlocks(const Vec3View& position, RowRange rows, BlockCoord* out) const {
  return std::any_of(modules_.begin(), modules_.end(),
                     [&](const auto& m) { return m->sampleBlocks(position, rows, out); });
}

void ForceSet::endTick(ParticlePool& pool, const TickInstant& end) {
  for (auto& m : modules_) m->endTick(pool, end);
}

}  // namespace tickfx
