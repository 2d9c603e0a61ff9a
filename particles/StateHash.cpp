#include "particles/StateHash.h"

#include <cstdio>
#include <cstring>
#include <utility>

#include "particles/ParticleSystem.h"

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
  // A null column is rows zeros (+0.0f): a column the pool does not keep.
  void addFloats(const FloatColumn* column, std::size_t rows) {
    if (column == nullptr) {
      for (std::size_t i = 0; i < rows; ++i) add(0);
      return;
    }
    for (std::size_t i = 0; i < rows; ++i) {
      std::uint32_t bits = 0;
      std::memcpy(&bits, &(*column)[static_cast<Eigen::Index>(i)], sizeof bits);
      add(bits);
    }
  }
  std::uint64_t value() const { return h_; }

 private:
  std::uint64_t h_ = 0xcbf29ce484222325ULL;
};

// The float columns in stateHash()'s order, with their names; null for a column the pool does not
// keep (acceleration before velocity Verlet), whose values are all zero.
std::vector<std::pair<std::string, const FloatColumn*>> floatColumns(const ParticlePool& pool) {
  std::vector<std::pair<std::string, const FloatColumn*>> columns;
  const std::pair<const char*, const Vec3Column*> vectors[] = {
      {"position", &pool.position()},
      {"velocity", &pool.velocity()},
      {"previous_position", &pool.previousPosition()},
      {"acceleration", pool.keepsAcceleration() ? &pool.acceleration() : nullptr}};
  for (const auto& [name, column] : vectors) {
    for (int k = 0; k < 3; ++k) {
      columns.emplace_back(std::string(name) + "." + "xyz"[k],
                           column != nullptr ? &(*column)[k] : nullptr);
    }
  }
  columns.emplace_back("age", &pool.age());
  columns.emplace_back("lifetime", &pool.lifetime());
  columns.emplace_back("mass", &pool.mass());
  columns.emplace_back("inverse_mass", &pool.inverseMass());
  for (std::size_t a = 0; a < pool.attributeCount(); ++a)
    columns.emplace_back("attribute." + pool.attributeName(a), &pool.attribute(a));
  return columns;
}

void addPool(Hasher& h, const ParticlePool& pool);

}  // namespace

std::uint64_t stateHash(const ParticlePool& pool) {
  Hasher h;
  addPool(h, pool);
  return h.value();
}

std::uint64_t stateHash(const ParticleSystem& system) {
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
  for (const auto& column : floatColumns(pool)) h.addFloats(column.second, n);
}

}  // namespace

std::vector<std::string> stateColumnNames(const ParticlePool& pool) {
  std::vector<std::string> names = {"counters", "id", "birth_tick"};
  for (const auto& column : floatColumns(pool)) names.push_back(column.first);
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
  for (const auto& column : floatColumns(pool)) {
    Hasher h;
    h.add(n);
    h.addFloats(column.second, n);
    hashes.push_back(h.value());
  }
  return hashes;
}

std::vector<std::uint64_t> stateRowBits(const ParticlePool& pool, std::size_t row) {
  std::vector<std::uint64_t> bits = {pool.id()[row],
                                     static_cast<std::uint64_t>(pool.birthTick()[row])};
  for (const auto& column : floatColumns(pool)) {
    std::uint32_t b = 0;  // +0.0f in a column the pool does not keep
    if (column.second != nullptr)
      std::memcpy(&b, &(*column.second)[static_cast<Eigen::Index>(row)], sizeof b);
    bits.push_back(b);
  }
  return bits;
}

std::string hashToHex(std::uint64_t hash) {
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(hash));
  return text;
}

}  // namespace tickfx
