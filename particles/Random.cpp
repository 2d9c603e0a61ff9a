#include "particles/Random.h"

namespace tickfx {
std::uint64_t randomBits(const RandomKey& key) {
  // Each coordinate goes through a full mixing round before the next is folded in, so keys that
  // differ in one coordinate by one give unrelated outputs (no lattice structure between serials).
  std::uint64_t h = splitmix64(key.seed);
  h = mix64(h ^ (static_cast<std::uint64_t>(key.emitter) * 0xd1b54a32d192ed03ULL + 1));
  h = mix64(h ^ (key.serial * 0xaef17502108ef2d9ULL + 2));
  h = mix64(h ^ (static_cast<std::uint64_t>(key.purpose) * 0xf1357aea2e62a9c5ULL + 3));
  return h;
}

double randomUniform(const RandomKey& key) { return uniformFromBits(randomBits(key)); }

}  // namespace tickfx
