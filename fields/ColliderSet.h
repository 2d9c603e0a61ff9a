// The colliders of a system and the collision pass of a tick.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <span>
#include "fields/Collider.h"
#include "particles/ParticleEvent.h"
#include "particles/ParticlePool.h"
#include "particles/StartsSpan.h"

namespace tickfx {

/// The most contacts a particle makes in one tick. After the last it stays where that contact
/// placed it on the collider, carried along for the rest of the tick if the collider moves (a
/// particle wedged between colliders cannot loop).
inline constexpr int kMaxContactsPerTick = 4;

/// Houdini's hit attributes, as columns of the pool: `hitnum` (the contacts so far, a whole
/// number), `hittime` (s: the time of the last contact), `hitpos` (m: the particle's centre at
/// it), `hitnml` (the surface's unit normal there, towards the side particles stay on) and `hitv`
/// (m/s: the velocity just before that contact's response), each vector as three columns
/// `<name>_x`, `_y`, `_z`. Only contacts with a collider that records hits count.
inline constexpr std::array<const char*, 11> kHitColumns = {
    "hitnum",   "hittime",  "hitpos_x", "hitpos_y", "hitpos_z", "hitnml_x",
    "hitnml_y", "hitnml_z", "hitv_x",   "hitv_y",   "hitv_z"};

/// Where a particle went within the last tick when it touched a collider: from `start` through
/// each contact point at its fraction of the tick, to its position after the tick. Render copies
/// between ticks follow this polyline, so a frame never shows a bounced particle on the straight
/// line from start to end, which may cut through the collider.
struct CollisionPath {
  std::uint64_t id = 0;
  Eigen::Vector3f start = Eigen::Vector3f::Zero();
  int contacts = 0;
  std::array<float, kMaxContactsPerTick> fraction{};
  // (Each zero: Eigen leaves a default-constructed vector's values unset, and a path's bits
  // should not depend on the stack it was made on.)
  std::array<Eigen::Vector3f, kMaxContactsPerTick> point = [] {
    std::array<Eigen::Vector3f, kMaxContactsPerTick> zero;
    zero.fill(Eigen::Vector3f::Zero());
    return zero;
  }();

  /// The position at fraction `alpha` in [0, 1] of the tick, `end` being the tick's: exactly
  /// `start` at 0 and `end` at 1, linear between consecutive points.
  Eigen::Vector3f at(float alpha, const Eigen::Vector3f& end) const;
};

/// Owns the colliders of a system and runs them after each tick's step.
class ColliderSet {
 public:
  ColliderSet();
  ~ColliderSet();
  ColliderSet(ColliderSet&&) noexcept;
  ColliderSet& operator=(ColliderSet&&) noexcept;

  /// Appends `collider` (taking ownership); returns it. Earlier colliders win ties.
  Collider& add(std::unique_ptr<Collider> collider);
  std::size_t size() const { return colliders_.size(); }
  bool empty() const { return colliders_.empty(); }
  const Collider& collider(std::size_t i) const { return *colliders_[i]; }
  /// Whether a collider records hits (ColliderSettings::recordHits).
  bool recordsHits() const;
  /// Adds kHitColumns to `pool` (each 0 for every row) when a collider records hits; otherwise
  /// the pool keeps its columns, and a particle its bytes.
  void addHitColumns(ParticlePool& pool) const;

  /// The tick's collisions, after the integrator moved rows [0, pool.size()) from
  /// previousPosition() to position(). Each row's path is tested against every collider; at the
  /// earliest contact the particle is placed there, its velocity responded (Collider::respond) and
  /// the rest of the tick continued from there at the new velocity, up to kMaxContactsPerTick
  /// contacts. A kill contact flags the particle dead (bit 1) at the contact. Rows are
  /// independent: any thread count gives the same bits. When `history` (position Verlet, whose
  /// previous position is its velocity), a row that touched gets previous = position − v·dt, so
  /// that its next step carries the responded velocity. Hits are recorded in the pool's hit
  /// columns where it has them (addHitColumns), the tick starting at tick / stepRateHz seconds.
  /// The pool must keep previous positions (ParticlePool::keepPrevious(); a ParticleSystem with
  /// colliders does): std::invalid_argument otherwise.
  void collide(ParticlePool& pool, std::int64_t tick, std::int64_t stepRateHz, bool history);

  /// collide() in three parts, for a caller that collides each block of rows right after its
  /// step, while the block is in cache: beginTick() once, collideRows() for disjoint blocks
  /// [begin, end) of at most kParallelBlockRows rows, each begin a multiple of it, from any
  /// threads at once, then endTick(). No spawn or removal in between. The same bits as collide().
  /// The paths start at `starts` where given (x, y, z: row r's at index r − begin; the step's
  /// StepRows::starts, so that a tick no frame interpolates across leaves the pool's column
  /// alone), else at the pool's previousPosition(), which must then be kept.
  /// With `written` (a block's StepRows::written after its step, bit k for rows begin + 128k on),
  /// only the groups of rows whose bit is set are screened: the step wrote the others' starts on
  /// the span's axis alone, and startsSpan() rules out every path among them.
  void beginTick(ParticlePool& pool, std::int64_t tick, std::int64_t stepRateHz, bool history);
  void collideRows(ParticlePool& pool, std::size_t begin, std::size_t end,
                   const std::array<const float*, 3>& starts = {},
                   std::uint64_t written = ~std::uint64_t{0});
  void endTick();
  /// The span of this tick (after beginTick()) outside which no collider's screen flags a path
  /// (Collider::screenSpan()): on y where every collider bounds its screen there, else x, else
  /// z; none where some collider bounds it on no axis (a moving one, a container).
  const StartsSpan& startsSpan() const { return tick_.span; }

  /// From the next tick on, records every contact (ContactRecord) for collision events, and counts
  /// each particle's contacts in the pool column `countColumn` (a float attribute the caller
  /// added; a contact's ordinal is the count before it).
  void recordContacts(const std::string& countColumn) { countColumn_ = countColumn; }
  /// The last collide()'s contacts when recorded: one list a block of kParallelBlockRows rows,
  /// each in row order and, within a row, in the order they happened. Empty otherwise.
  std::span<const std::vector<ContactRecord>> contactBlocks() const {
    if (countColumn_.empty()) return {};
    return {blockContacts_.data(), tick_.blocks};
  }

  /// The paths of the rows that touched a collider in the last collide(): one list a block of
  /// kParallelBlockRows rows, each in row order. Kept as the blocks found them: a tick whose
  /// rows all touch (a heap resting on the ground) would otherwise copy every path once more,
  /// on one thread.
  std::span<const std::vector<CollisionPath>> pathBlocks() const {
    return {blockPaths_.data(), tick_.blocks};
  }
  /// pathBlocks() in one list, in row order: a copy, for tests and diagnostics.
  std::vector<CollisionPath> paths() const;
  /// Contacts made in the last collide().
  std::uint64_t contacts() const { return contacts_; }

 private:
  // What beginTick() sets for the tick's collideRows().
  struct TickState {
    float dt = 0.0f;     // s
    float start = 0.0f;  // s: the tick's start, for hittime
    bool history = false;
    bool kills = false;  // some collider's response is Kill
    std::size_t blocks = 0;
    std::array<float*, kHitColumns.size()> hits{};  // the pool's hit columns, or null
    float* counts = nullptr;                        // the contact count column, or null
    StartsSpan span;
  };

  std::vector<std::unique_ptr<Collider>> colliders_;
  TickState tick_;
  std::vector<std::vector<CollisionPath>> blockPaths_;
  std::vector<std::uint64_t> blockContactCounts_;  // contacts a block made, by collideRows()
  std::string countColumn_;                        // empty: contacts not recorded
  std::vector<std::vector<ContactRecord>> blockContacts_;
  std::uint64_t contacts_ = 0;
};

}  // namespace tickfx
