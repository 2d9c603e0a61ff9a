// Damped springs between particles: ropes, cloth, soft clusters.
#pragma once

#include <cstdint>
#include <vector>

#include "fields/ForceModule.h"
#include "particles/Spring.h"

namespace tickfx {

/// Damped Hooke springs between particles: on particle i, from its spring to j,
///   F = (k · (|d| − L) + c · (v_j − v_i)·d̂) · d̂,   d = p_j − p_i,   a_i += F / m_i.
///
/// Gather, not scatter: each particle sums the forces of its own springs, in the order the springs
/// were added, reading its partners' state; the two ends of a spring compute exactly opposite
/// forces (d and −d have the same length bits). So the result does not depend on the thread
/// count, and the module is not local (isLocal() is false: integrators run split passes).
///
/// Springs are kept by particle id: at the start of each tick (beginTick) the module maps ids to
/// rows, removes springs whose ends have died, breaks springs stretched past their ratio (from the
/// state at the start of the tick), and rebuilds each particle's list. A particle with inverse
/// mass 0 (pinned) gets no acceleration from springs; ForceSet zeroes every other force on it too.
class SpringNetwork final : public ForceModule {
 public:
  std::string_view typeName() const override { return "springs"; }
  bool isLocal() const override { return false; }
  void beginTick(const ParticlePool& pool, std::int64_t tick) override;
  void accumulate(const ForceInput& in, RowRange rows, Vec3Rows& acceleration) const override;

  /// Adds a spring (ends may be spawned later; until both exist it does nothing).
  void add(const Spring& spring) {
    springs_.push_back(spring);
    built_ = false;
  }
  /// Springs still in the network (dead ends and broken ones are removed at beginTick).
  const std::vector<Spring>& springs() const { return springs_; }
  /// Springs broken by stretching since construction.
  std::uint64_t brokenCount() const { return broken_; }
  /// Replaces the whole network (restoring a saved state).
  void restore(std::vector<Spring> springs, std::uint64_t broken) {
    springs_ = std::move(springs);
    broken_ = broken;
    built_ = false;
  }

 private:
  struct Link {
    std::uint32_t other;   // row of the other end
    std::uint32_t spring;  // index into springs_
  };

  struct Ends {
    std::uint32_t a, b, spring;  // the rows of a spring's ends, and the spring's index
  };

  bool tablesStillHold(const ParticlePool& pool) const;
  void rebuild(const ParticlePool& pool);

  std::vector<Spring> springs_;
  std::uint64_t broken_ = 0;
  // Row → [first_[row], first_[row+1]) in links_, in spring order; rebuilt when rows moved, ends
  // were born or died, or a spring broke (beginTick), else kept from the tick before.
  std::vector<std::uint32_t> first_;
  std::vector<Link> links_;
  std::vector<Ends> ends_;  // the springs with both ends alive, in spring order
  bool built_ = false;
  bool breakable_ = false;       // some spring has a break ratio
  std::size_t pendingEnds_ = 0;  // springs kept for an end not born yet
  std::uint64_t builtRowsVersion_ = 0;
  std::uint64_t builtNextId_ = 0;
};

}  // namespace tickfx
