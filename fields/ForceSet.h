// An ordered list of force modules evaluated as one.
#pragma once

#include <memory>
#include <vector>

#include "fields/ForceModule.h"

namespace tickfx {

/// Owns the force modules of a system and evaluates them in insertion order.
class ForceSet {
 public:
  ForceSet() = default;
  ForceSet(ForceSet&&) noexcept = default;
  ForceSet& operator=(ForceSet&&) noexcept = default;

  /// Appends `module` (taking ownership); returns it for further configuration.
  ForceModule& add(std::unique_ptr<ForceModule> module);

  std::size_t size() const { return modules_.size(); }
  const ForceModule& module(std::size_t i) const { return *modules_[i]; }
  ForceModule& module(std::size_t i) { return *modules_[i]; }

  /// True when every module is local (see ForceModule::isLocal).
  bool isLocal() const;

  /// Once per tick before any evaluation: the modules' beginTick, and whether any particle is
  /// pinned (inverse mass 0), which evaluate() then holds still.
  void beginTick(const ParticlePool& pool, std::int64_t tick);

  /// Writes the total acceleration at `in` for rows `rows` into `acceleration` (overwrites):
  /// 0 + a_1 + a_2 + ... in module order, for every row; 0 for pinned particles.
  void evaluate(const ForceInput& in, RowRange rows, Vec3Rows& acceleration) const;

 private:
  std::vector<std::unique_ptr<ForceModule>> modules_;
  bool anyPinned_ = false;
};

}  // namespace tickfx
