// A fingerprint of the simulation state, for determinism tests.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "particles/ParticlePool.h"

namespace tickfx {

/// A 64-bit hash over the bits of every column of rows [0, size()) in id order (the pool's row
/// order), plus the row count, the next id and the dropped-spawn count. Each column is hashed in
/// fixed blocks of 65536 rows, in parallel: a block's words are dealt in turn to four chains, and
/// its hash chains the four; a column's hash chains the row count and its blocks' hashes, and the
/// state's chains the counters and the columns' hashes in stateColumnNames() order.
/// The value depends on the bits alone, never on the thread count. Ages and inverse masses
/// count as the columns they once were (worked out from birth ticks and masses); the previous
/// position counts as zeros unless it is state (ParticlePool::previousIsState()). Two states hash
/// equal only if (barring collisions) every float is bitwise equal; −0 and +0 differ, as they
/// should.
std::uint64_t stateHash(const ParticlePool& pool);

class ParticleSystem;
/// The state hash of a whole system: stateHash(system.pool()) when no sub-emitter event waits
/// for the next tick, else that hash continued over the pending events (EventEmission::pending():
/// each event's parent id, emitter, kind, ordinal, position, velocity, normal and inherited
/// values), which are state too: the next tick's children come from them.
std::uint64_t stateHash(const ParticleSystem& system);

/// The columns stateHash() covers, in its order, so a difference can be named: "counters" (row
/// count, next id, dropped spawns), "id", "birth_tick", "position.x" ... "acceleration.z", "age",
/// "lifetime", "mass", "inverse_mass", then "attribute.NAME" for each custom attribute.
std::vector<std::string> stateColumnNames(const ParticlePool& pool);

/// One hash per column of stateColumnNames(), each over the row count and that column's bits
/// alone: two states whose stateHash() differs differ in the columns whose hashes differ.
std::vector<std::uint64_t> stateColumnHashes(const ParticlePool& pool);

/// The bits of row `row` in every column but "counters" (the first of stateColumnNames()): the
/// id, the birth tick as two's complement, and each float's 32 bits.
std::vector<std::uint64_t> stateRowBits(const ParticlePool& pool, std::size_t row);

/// `hash` as 16 lowercase hex digits.
std::string hashToHex(std::uint64_t hash);

}  // namespace tickfx
