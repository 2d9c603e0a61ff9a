#include "particles/StateHash.h"

#include <algorithm>
#include <bit>
#include <cstdio>
#include <cstring>
#include <utility>

#include "particles/ParticleSystem.h"
#include "particles/PhaseProfile.h"

namespace tickfx {
namespace {

// Word-at-a-time mixing: every input word passes a full avalanche, so a single flipped bit in
// any column changes the result.
// A float column stateHash() covers: one the pool stores, one it does not keep (acceleration
// before velocity Verlet: all +0.0f), or one worked out from others (ages from birth ticks at the
// pool's clock, inverse masses from masses), which hashes as the column it replaced did.
struct HashedColumn {
  enum class Kind { Stored, Zero, Age, InverseMass };
  std::string name;
  Kind kind = Kind::Stored;
  const FloatColumn* stored = nullptr;

  // Rows [begin, end) into out[0, end − begin).
  void values(const ParticlePool& pool, std::size_t begin, std::size_t end, float* out) const {
    switch (kind) {
      case Kind::Stored:
        std::memcpy(out, stored->data() + begin, (end - begin) * sizeof(float));
        break;
      case Kind::Zero:
        std::fill(out, out + (end - begin), 0.0f);
        break;
      case Kind::Age:
        pool.ages(begin, end, out);
        break;
      case Kind::InverseMass:
        for (std::size_t i = begin; i < end; ++i)
          out[i - begin] = inverseMassOf(pool.mass()[static_cast<Eigen::Index>(i)]);
        break;
    }
  }
};

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
  // Each value's 32 bits, in chunks: a worked-out column never exists whole.
  void addFloats(const ParticlePool& pool, const HashedColumn& column, std::size_t rows) {
    constexpr std::size_t kRowsAtOnce = 4096;
    float chunk[kRowsAtOnce];
    for (std::size_t b = 0; b < rows; b += kRowsAtOnce) {
      const std::size_t e = std::min(rows, b + kRowsAtOnce);
      column.values(pool, b, e, chunk);
      for (std::size_t i = 0; i < e - b; ++i) add(std::bit_cast<std::uint32_t>(chunk[i]));
    }
  }
  std::uint64_t value() const { return h_; }

 private:
  std::uint64_t h_ = 0xcbf29ce484222325ULL;
};

// The float columns in stateHash()'s order.
std::vector<HashedColumn> floatColumns(const ParticlePool& pool) {
  using Kind = HashedColumn::Kind;
  std::vector<HashedColumn> columns;
  // The previous position is state only where the scheme reads it (position Verlet); elsewhere
  // it is what the newest frame between ticks interpolates from, kept only by the ticks such a
  // frame needs, and the same state after tick k whatever the frames carries zeros here.
  const std::pair<const char*, const Vec3Column*> vectors[] = {
      {"position", &pool.position()},
      {"velocity", &pool.velocity()},
      {"previous_position", pool.previousIsState() ? &pool.previousPosition() : nullptr},
      {"acceleration", pool.keepsAcceleration() ? &pool.acceleration() : nullptr}};
  for (const auto& [name, column] : vectors) {
    for (int k = 0; k < 3; ++k) {
      columns.push_back({std::string(name) + "." + "xyz"[k],
                         column != nullptr ? Kind::Stored : Kind::Zero,
                         column != nullptr ? &(*column)[k] : nullptr});
    }
  }
  columns.push_back({"age", Kind::Age});
  columns.push_back({"lifetime", Kind::Stored, &pool.lifetime()});
  columns.push_back({"mass", Kind::Stored, &pool.mass()});
  columns.push_back({"inverse_mass", Kind::InverseMass});
  for (std::size_t a = 0; a < pool.attributeCount(); ++a)
    columns.push_back({"attribute." + pool.attributeName(a), Kind::Stored, &pool.attribute(a)});
  return columns;
}

void addPool(Hasher& h, const ParticlePool& pool);

}  // namespace

std::uint64_t stateHash(const ParticlePool& pool) {
  const profile::PhaseScope phase(profile::Phase::Hash);
  Hasher h;
  addPool(h, pool);
  return h.value();
}

std::uint64_t stateHash(const ParticleSystem& system) {
  const profile::PhaseScope phase(profile::Phase::Hash);
  Hasher h;
  addPool(h, system.pool());
  const EventEmission* events = system.events();
  if (events == nullptr || events->pending().empty()) return h.value();
  const auto floatBits = [](float f) {
    std::uint32_t b = 0;
    std::memcpy(&b, &f, sizeof b);
    return static_cast<std::uint64_t>(b);
  };
  h.add(events->pending().size());
  for (const ParticleEvent& e : events->pending()) {
    h.add(e.parentId);
    h.add(e.parentEmitter);
    h.add(static_cast<std::uint64_t>(e.kind));
    h.add(e.ordinal);
    for (const Eigen::Vector3f* v : {&e.position, &e.velocity, &e.normal}) {
      for (int c = 0; c < 3; ++c) h.add(floatBits((*v)[c]));
    }
  }
  for (const float f : events->pendingValues()) h.add(floatBits(f));
  return h.value();
}

namespace {

void addPool(Hasher& h, const ParticlePool& pool) {
  const std::size_t n = pool.size();
  h.add(n);
  h.add(pool.nextId());
  h.add(pool.droppedSpawns());
  for (std::size_t i = 0; i < n; ++i) h.add(pool.id()[i]);
  for (std::size_t i = 0; i < n; ++i) h.add(static_cast<std::uint64_t>(pool.birthTick()[i]));
  for (const HashedColumn& column : floatColumns(pool)) h.addFloats(pool, column, n);
}

}  // namespace

std::vector<std::string> stateColumnNames(const ParticlePool& pool) {
  std::vector<std::string> names = {"counters", "id", "birth_tick"};
  for (const HashedColumn& column : floatColumns(pool)) names.push_back(column.name);
  return names;
}

std::vector<std::uint64_t> stateColumnHashes(const ParticlePool& pool) {
  const std::size_t n = pool.size();
  std::vector<std::uint64_t> hashes;
  Hasher counters;
  counters.add(n);
  counters.add(pool.nextId());
  counters.add(pool.droppedSpawns());
  hashes.push_back(counters.value());
  Hasher ids, births;
  ids.add(n);
  births.add(n);
  for (std::size_t i = 0; i < n; ++i) ids.add(pool.id()[i]);
  for (std::size_t i = 0; i < n; ++i) births.add(static_cast<std::uint64_t>(pool.birthTick()[i]));
  hashes.push_back(ids.value());
  hashes.push_back(births.value());
  for (const HashedColumn& column : floatColumns(pool)) {
    Hasher h;
    h.add(n);
    h.addFloats(pool, column, n);
    hashes.push_back(h.value());
  }
  return hashes;
}

std::vector<std::uint64_t> stateRowBits(const ParticlePool& pool, std::size_t row) {
  std::vector<std::uint64_t> bits = {pool.id()[row],
                                     static_cast<std::uint64_t>(pool.birthTick()[row])};
  for (const HashedColumn& column : floatColumns(pool)) {
    float value = 0.0f;
    column.values(pool, row, row + 1, &value);
    bits.push_back(std::bit_cast<std::uint32_t>(value));
  }
  return bits;
}

std::string hashToHex(std::uint64_t hash) {
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(hash));
  return text;
}

}  // namespace tickfx
