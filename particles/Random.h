// Counter-based random numbers: a value is a pure function of its coordinates.
#pragma once

#include <bit>
#include <cstdint>

namespace tickfx {

/// What a random number is for. Each purpose draws from its own stream, so adding a draw for one
/// purpose never shifts the values of another.
enum class RandomPurpose : std::uint32_t {
  PositionU = 1,
  PositionV = 2,
  PositionW = 3,
  DirectionU = 4,
  DirectionV = 5,
  Speed = 6,
  Lifetime = 7,
  Mass = 8,
  ChildCount = 9,   // a sub-emitter's children per event, drawn from count_range
  Custom = 64,      // Custom + k for user-defined draws
  Attribute = 128,  // Attribute + k for an emitter's k-th attribute over life
};

/// The coordinates of one random number. Nothing here depends on the frame, the thread or the
/// order of calls, which is what lets a particle's birth look the same under any schedule.
struct RandomKey {
  std::uint64_t seed = 0;     // the effect's seed
  std::uint32_t emitter = 0;  // index of the emitter in the effect
  std::uint64_t serial = 0;   // the emitter's count of particles before this one
  std::uint32_t purpose = 0;  // a RandomPurpose
};

/// SplitMix64's finaliser (Stafford's variant 13): a bijection of 64 bits in which every input bit
/// flips about half the output bits. The building block of every hash-like draw in tickfx.
constexpr std::uint64_t mix64(std::uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

/// One SplitMix64 output for state `x`: mix64(x + the golden-ratio increment).
constexpr std::uint64_t splitmix64(std::uint64_t x) { return mix64(x + 0x9e3779b97f4a7c15ULL); }

/// 64 well-mixed bits for `key` (a keyed SplitMix64-style finaliser over the four coordinates).
std::uint64_t randomBits(const RandomKey& key);

/// Uniform in [0, 1) with 53 random bits; pure function of `key`.
double randomUniform(const RandomKey& key);

/// Uniform in [0, 1) with 53 random bits: (bits >> 11) · 2^-53, exactly.
///
/// Worked out in operations every vector unit has, since a cast from a 64-bit integer has no SSE2
/// or AVX2 vector form and would keep the emitters' batch loops scalar. The top 52 of the 53 bits
/// become the mantissa of a double in [1, 2), from which 1 is taken (exact: both are in [1, 2));
/// the 53rd bit is added as 2^-53 or 0 (exact: the sum is a multiple of 2^-53 below 1).
inline double uniformFromBits(std::uint64_t bits) {
  const double top = std::bit_cast<double>(0x3ff0000000000000ULL | (bits >> 12)) - 1.0;
  const double last = std::bit_cast<double>((bits & 0x800ULL) == 0x800ULL ? 0x3ca0000000000000ULL
                                                                          : std::uint64_t{0});
  return top + last;
}

/// The first rounds of a particle's key, those that mix in the seed and the emitter: the same for
/// all of an emitter's particles, so a batch of them works it out once (particleKey()).
std::uint64_t emitterKey(std::uint64_t seed, std::uint32_t emitter);

/// The key of the particle of serial `serial`, from its emitter's emitterKey().
constexpr std::uint64_t particleKey(std::uint64_t emitterKey, std::uint64_t serial) {
  return mix64(emitterKey ^ (serial * 0xaef17502108ef2d9ULL + 2));
}

/// 64 random bits for `purpose` of the particle whose key is `particleKey`.
constexpr std::uint64_t purposeBits(std::uint64_t particleKey, std::uint32_t purpose) {
  return mix64(particleKey ^ (static_cast<std::uint64_t>(purpose) * 0xf1357aea2e62a9c5ULL + 3));
}

/// The draws of one particle: randomBits() and randomUniform() for (seed, emitter, serial) and any
/// purpose, the same values, with the rounds that mix in the first three coordinates done once
/// rather than once a draw.
class ParticleRandom {
 public:
  ParticleRandom(std::uint64_t seed, std::uint32_t emitter, std::uint64_t serial);
  std::uint64_t bits(std::uint32_t purpose) const { return purposeBits(mixed_, purpose); }
  double uniform(std::uint32_t purpose) const { return uniformFromBits(bits(purpose)); }

 private:
  std::uint64_t mixed_;
};

}  // namespace tickfx
