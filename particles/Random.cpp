#include "particles/Random.h"

namespace tickfx {

// Each coordinate goes through a full mixing round before the next is folded in, so keys that
// differ in one coordinate by one give unrelated outputs (no lattice structure between serials).
std::uint64_t emitterKey(std::uint64_t seed, std::uint32_t emitter) {
  return mix64(splitmix64(seed) ^
               (static_cast<std::uint64_t>(emitter) * 0xd1b54a32d192ed03ULL + 1));
}

ParticleRandom::ParticleRandom(std::uint64_t seed, std::uint32_t emitter, std::uint64_t serial)
    : mixed_(particleKey(emitterKey(seed, emitter), serial)) {}

std::uint64_t randomBits(const RandomKey& key) {
  return ParticleRandom(key.seed, key.emitter, key.serial).bits(key.purpose);
}

double randomUniform(const RandomKey& key) { return uniformFromBits(randomBits(key)); }

}  // namespace tickfx
