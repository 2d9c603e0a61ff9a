// A fingerprint of the simulation state, for determinism tests.
#pragma once

#include <cstdint>
#include <string>

#include "particles/ParticlePool.h"

namespace tickfx {

/// A 64-bit hash over the bits of every column of rows [0, size()) in id order (the pool's row
/// order), plus the row count, the next id and the dropped-spawn count. Two states hash equal
/// only if (barring collisions) every float is bitwise equal; −0 and +0 differ, as they should.
std::uint64_t stateHash(const ParticlePool& pool);

/// `hash` as 16 lowercase hex digits.
std::string hashToHex(std::uint64_t hash);

}  // namespace tickfx
