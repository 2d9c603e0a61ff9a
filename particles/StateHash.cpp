#include "particles/StateHash.h"

#include <cstdio>
#include <cstring>

namespace tickfx {
namespace {

// Word-at-a-time mixing: every input word passes a full avalanche, so a single flipped bit in
// any column changes the result.
class Hasher {
 public:
  void add(std::uint64_t word) {
    h_ = (h_ ^ word) * 0x100000001b3ULL;
    h_ ^= h_ >> 29;
    h_ *= 0xbf58476d1ce4e5b9ULL;
    h_ ^= h_ >> 32;
  }
  void addFloats(const FloatColumn& column, std::size_t rows) {
    for (std::size_t i = 0; i < rows; ++i) {
      std::uint32_t bits = 0;
      std::memcpy(&bits, &column[static_cast<Eigen::Index>(i)], sizeof bits);
      add(bits);
    }
  }
  std::uint64_t value() const { return h_; }

 private:
  std::uint64_t h_ = 0xcbf29ce484222325ULL;
};

}  // namespace

std::uint64_t stateHash(const ParticlePool& pool) {
  Hasher h;
  const std::size_t n = pool.size();
  h.add(n);
  h.add(pool.nextId());
  h.add(pool.droppedSpawns());
  for (std::size_t i = 0; i < n; ++i) h.add(pool.id()[i]);
  for (std::size_t i = 0; i < n; ++i) h.add(static_cast<std::uint64_t>(pool.birthTick()[i]));
  for (const Vec3Column* c :
       {&pool.position(), &pool.velocity(), &pool.previousPosition(), &pool.acceleration()}) {
    for (int k = 0; k < 3; ++k) h.addFloats((*c)[k], n);
  }
  for (const FloatColumn* c : {&pool.age(), &pool.lifetime(), &pool.mass(), &pool.inverseMass()}) {
    h.addFloats(*c, n);
  }
  for (std::size_t a = 0; a < pool.attributeCount(); ++a) h.addFloats(pool.attribute(a), n);
  return h.value();
}

std::string hashToHex(std::uint64_t hash) {
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(hash));
  return text;
}

}  // namespace tickfx
