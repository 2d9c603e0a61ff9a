// Sub-emitters at run time: the events of a tick and the children they make.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "particles/Emitter.h"
#include "particles/LifeAttributeSet.h"
#include "particles/ParticleEvent.h"
#include "particles/ParticlePool.h"

namespace tickfx {

/// The column that counts a particle's contacts with any collider (a whole number), kept when a
/// sub-emitter emits on collisions: the ordinal of a contact is its count before it.
inline constexpr const char* kContactsColumn = "contacts";

/// What the sub-emitters of `emitters` refuse as a whole, keyed "<index>.parent" or
/// "<index>.inherit.<k>" (index into `emitters`): a parent that is not an emitter's name, a cycle
/// of parents, a chain deeper than kMaxSubEmitterDepth, an inherited attribute that the parent
/// neither declares, inherits nor finds among `columns` (names of the pool's columns; "Cd" and
/// vectors such as "hitpos" stand for their components).
SettingProblems validateSubEmitters(const std::vector<EmitterSettings>& emitters,
                                    const std::vector<std::string>& columns);

/// The sub-emitters of a system. In a tick, the system calls spawn() after the emitters' births,
/// and gather() after ages are updated and before the dead are removed. The children of a tick
/// are appended in order: first those of the previous tick's events (pending()), ordered by
/// (parent id, kind: contacts before the death, ordinal, sub-emitter index, child index); then
/// the children of the tick's births, in the same order, round after round for children that are
/// themselves parents of birth events. Each step counts per block of events, sums the counts in
/// order and fills its rows in parallel, so rows, ids and bits do not depend on the threads.
/// Children the pool has no room for are counted as refused spawns (the first ones in that order
/// are kept).
class EventEmission {
 public:
  EventEmission() = default;
  /// Adds the pool columns the sub-emitters need (kContactsColumn, inherited attributes) and
  /// throws std::invalid_argument with the first of validateSubEmitters().
  EventEmission(const std::vector<Emitter>& emitters, const LifeAttributeSet* attributes,
                std::uint64_t seed, ParticlePool& pool);

  bool empty() const { return subEmitters_ == 0; }
  bool listensTo(EmitterEvent kind) const { return listening_[static_cast<std::size_t>(kind)]; }

  /// The children of tick `tick`: of the pending events, then of the births among rows
  /// [firstNew, pool.size()) and of theirs.
  void spawn(ParticlePool& pool, std::int64_t tick, std::size_t firstNew);
  /// The tick's deaths (rows flagged dead, not for being non-finite) and contacts (`contacts`,
  /// one list a block of kParallelBlockRows rows, each in row order) of parents listened to,
  /// kept as pending() for the next tick.
  void gather(const ParticlePool& pool, std::span<const std::vector<ContactRecord>> contacts);

  /// Events whose children the next tick makes, and per event the parent's inherited values
  /// (inheritedColumns() of them, in that order): state, kept by checkpoints.
  const std::vector<ParticleEvent>& pending() const { return pending_; }
  const std::vector<float>& pendingValues() const { return pendingValues_; }
  const std::vector<std::string>& inheritedColumns() const { return inherited_; }
  /// Replaces the pending events (a restored checkpoint); values hold inheritedColumns() a event.
  void restorePending(std::vector<ParticleEvent> events, std::vector<float> values);

 private:
  struct Listener {
    std::uint32_t emitter = 0;
    std::vector<std::size_t> inherit;  // indices into inherited_, one per column copied
  };
  // The events of a list of parents, made in parallel blocks and joined in order.
  struct EventList {
    std::vector<ParticleEvent> events;
    std::vector<float> values;
  };
  const std::vector<Listener>& listeners(std::uint32_t parent, EmitterEvent kind) const {
    return listeners_[static_cast<std::size_t>(kind)][parent];
  }
  // The columns the events of a tick read, looked up once for all its rows.
  struct Rows {
    const ParticlePool& pool;
    const float* emitters;                // kEmitterColumn
    std::vector<const float*> inherited;  // inherited_'s columns
  };
  Rows rowsOf(const ParticlePool& pool) const;
  // The emitter of row `row` when a sub-emitter listens to its events of `kind`, else −1.
  int listened(const Rows& rows, std::size_t row, EmitterEvent kind) const;
  // Appends `event` of row `row` and the row's inherited values at the event.
  void record(const Rows& rows, std::size_t row, ParticleEvent event,
              std::vector<ParticleEvent>& events, std::vector<float>& values) const;
  EventList births(const ParticlePool& pool, std::size_t begin, std::size_t end) const;
  void spawnChildren(ParticlePool& pool, std::int64_t tick, const EventList& list) const;

  const std::vector<Emitter>* emitters_ = nullptr;
  const LifeAttributeSet* attributes_ = nullptr;
  std::uint64_t seed_ = 0;
  std::size_t subEmitters_ = 0;
  std::array<bool, 4> listening_{};
  // [kind][parent emitter] → its sub-emitters for that kind, in index order.
  std::array<std::vector<std::vector<Listener>>, 4> listeners_;
  std::vector<std::string> inherited_;  // pool columns children copy
  std::vector<int> inheritedLife_;      // per inherited column: its LifeAttributeSet index or −1
  std::vector<ParticleEvent> pending_;
  std::vector<float> pendingValues_;
};

}  // namespace tickfx
