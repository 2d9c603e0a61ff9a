// An ordered list of force modules evaluated as one.
#pragma once

#include <memory>
#include <optional>
#include <vector>

#include "fields/ForceModule.h"

namespace tickfx {

/// Owns the force modules of a system and evaluates them in insertion order.
class ForceSet {
 public:
  ForceSet() = default;
  ForceSet(ForceSet&&) noexcept = default;
  ForceSet& operator=(ForceSet&&) noexcept = default;

  /// Appends `module` (taking ownership); returns it for further configuration. Throws
  /// std::invalid_argument when the set would mix modules that prescribe velocity (advection)
  /// with modules that add acceleration, naming both.
  ForceModule& add(std::unique_ptr<ForceModule> module);

  std::size_t size() const { return modules_.size(); }
  const ForceModule& module(std::size_t i) const { return *modules_[i]; }
  ForceModule& module(std::size_t i) { return *modules_[i]; }

  /// True when every module is local (see ForceModule::isLocal).
  bool isLocal() const;

  /// True when every module interleaves ticks (see ForceModule::interleavesTicks).
  bool interleavesTicks() const;
  /// True when every module is arithmetic only (see ForceModule::arithmeticOnly).
  bool arithmeticOnly() const;

  /// Once per tick before any evaluation: the modules' beginTick, and whether any particle is
  /// pinned (inverse mass 0), which evaluate() then holds still.
  void beginTick(const ParticlePool& pool, std::int64_t tick);

  /// Writes the total acceleration at `in` for rows `rows` into `acceleration` (overwrites):
  /// 0 + a_1 + a_2 + ... in module order, for every row; 0 for pinned particles.
  void evaluate(const ForceInput& in, RowRange rows, Vec3Rows& acceleration) const;

  /// The acceleration evaluate() writes, when it is that simple: the modules are a leading run of
  /// uniform modules (ForceModule::uniformAcceleration) and then at most one linear drag, and no
  /// particle is pinned. Each row's acceleration is then `uniform`, plus k·(air − v) with a drag:
  /// a scheme may form it inside its update loop, by the same operations, instead of in a pass
  /// of its own.
  struct UniformAndDrag {
    Eigen::Vector3f uniform = Eigen::Vector3f::Zero();  // m/s²
    bool drag = false;
    float k = 0.0f;                                 // 1/s
    Eigen::Vector3f air = Eigen::Vector3f::Zero();  // m/s
  };
  std::optional<UniformAndDrag> uniformAndDrag(const ForceInput& in) const;

  /// True when the modules prescribe velocity (advection): integrators then advance x' = u(x, t)
  /// with evaluateVelocity() instead of asking for accelerations.
  bool prescribesVelocity() const { return advects_; }

  /// Writes the total prescribed velocity at `in` for rows `rows` into `velocity` (overwrites):
  /// 0 + u_1 + u_2 + ... in module order; 0 for pinned particles.
  void evaluateVelocity(const ForceInput& in, RowRange rows, Vec3Rows& velocity) const;

  /// True when the modules prescribe velocity and each reads nothing but positions
  /// (ForceModule::velocityFromPositionsOnly): evaluateVelocityGathered() may then stand for
  /// evaluateVelocity().
  bool gathersVelocity() const { return advects_ && gathers_; }
  /// evaluateVelocity() at positions gathered from any pool rows: element j of `position` (a
  /// base-0 buffer) and of `velocity` belongs to pool row rows[j], j < velocity's size. Each row
  /// gets the bits evaluateVelocity() gives it. Only when gathersVelocity().
  void evaluateVelocityGathered(const ParticlePool& pool, const Vec3View& position,
                                const std::uint32_t* rows, TickInstant at,
                                Vec3Rows& velocity) const;

  /// The grid blocks of the first module that has some (ForceModule::sampleBlocks); false when
  /// no module has.
  bool sampleBlocks(const Vec3View& position, RowRange rows, BlockCoord* out) const;

  /// Once per tick after the step: the modules' endTick, in order (see ForceModule::endTick).
  void endTick(ParticlePool& pool, const TickInstant& end);

 private:
  // Sums the leading run of uniform modules into `uniform`; returns the index of the first other.
  std::size_t uniformPrefix(const ForceInput& in, Eigen::Vector3f& uniform) const;

  std::vector<std::unique_ptr<ForceModule>> modules_;
  bool anyPinned_ = false;
  bool advects_ = false;
  bool gathers_ = true;  // every module velocityFromPositionsOnly()
};

}  // namespace tickfx
