#include "particles/StateHash.h"

#include <algorithm>
#include <bit>
#include <cstdio>
#include <cstring>
#include <utility>

#include "particles/Assert.h"
#include "particles/ParallelFor.h"
#include "particles/ParticleSystem.h"
#include "particles/PhaseProfile.h"

namespace tickfx {
namespace {

// Rows a column is hashed in at once: each block's hash is made of four chains over its rows, and
// a column's hash is a chain over its blocks' hashes. The blocks are fixed by the row count alone,
// so blocks are hashed in parallel and the value never depends on the thread count.
constexpr std::size_t kHashBlockRows = std::size_t{1} << 16;

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
  std::uint64_t value() const { return h_; }

 private:
  std::uint64_t h_ = 0xcbf29ce484222325ULL;
};

// Four chains a block's words are dealt to in turn: the first word to the first chain, the fifth
// to the first again. Every add() continues where the last one left off.
class Lanes {
 public:
  template <typename T>
  void add(const T* words, std::size_t n) {
    std::size_t i = 0;
    for (; next_ != 0 && i < n; ++i) addOne(static_cast<std::uint64_t>(words[i]));
    for (; i + 4 <= n; i += 4) {
      lane_[0].add(static_cast<std::uint64_t>(words[i]));
      lane_[1].add(static_cast<std::uint64_t>(words[i + 1]));
      lane_[2].add(static_cast<std::uint64_t>(words[i + 2]));
      lane_[3].add(static_cast<std::uint64_t>(words[i + 3]));
    }
    for (; i < n; ++i) addOne(static_cast<std::uint64_t>(words[i]));
  }
  std::uint64_t value() const {
    Hasher h;
    for (const Hasher& lane : lane_) h.add(lane.value());
    return h.value();
  }

 private:
  void addOne(std::uint64_t word) {
    lane_[next_].add(word);
    next_ = (next_ + 1) % 4;
  }
  Hasher lane_[4];
  std::size_t next_ = 0;
};

// A column stateHash() covers: the ids, the birth ticks (as 64-bit words), a float column the pool
// stores, one it does not keep (acceleration before velocity Verlet: all +0.0f), or one worked
// out from others (ages from birth ticks at the pool's clock, inverse masses from masses), which
// hashes as the column it replaced did. Floats count as their 32 bits.
struct HashedColumn {
  enum class Kind { Id, BirthTick, Stored, Zero, Age, InverseMass };
  std::string name;
  Kind kind = Kind::Stored;
  const FloatColumn* stored = nullptr;

  // Float rows [begin, end) into out[0, end − begin).
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
      case Kind::Id:
      case Kind::BirthTick:
        TICKFX_ASSERT(false, "an integer column read as floats");
        break;
    }
  }

  // A block's hash: rows [begin, end) dealt to four chains (row begin + i to chain i mod 4, four
  // independent multiply chains at once instead of one), then the chain over the four.
  std::uint64_t hashRows(const ParticlePool& pool, std::size_t begin, std::size_t end) const {
    Lanes lanes;
    if (kind == Kind::Id) {
      lanes.add(pool.id().data() + begin, end - begin);
    } else if (kind == Kind::BirthTick) {
      lanes.add(pool.birthTick().data() + begin, end - begin);
    } else {
      // In chunks of a multiple of four rows: a worked-out column never exists whole.
      constexpr std::size_t kRowsAtOnce = 4096;
      std::uint32_t chunk[kRowsAtOnce];
      for (std::size_t b = begin; b < end; b += kRowsAtOnce) {
        const std::size_t e = std::min(end, b + kRowsAtOnce);
        values(pool, b, e, reinterpret_cast<float*>(chunk));
        lanes.add(chunk, e - b);
      }
    }
    return lanes.value();
  }
};

// Every column stateHash() covers, in its order.
std::vector<HashedColumn> hashedColumns(const ParticlePool& pool) {
  using Kind = HashedColumn::Kind;
  std::vector<HashedColumn> columns = {{"id", Kind::Id}, {"birth_tick", Kind::BirthTick}};
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

// Each column's hash: the chain over the row count and its blocks' hashes, the blocks hashed in
// parallel tasks (every block of every column one task).
std::vector<std::uint64_t> columnHashes(const ParticlePool& pool) {
  const std::vector<HashedColumn> columns = hashedColumns(pool);
  const std::size_t n = pool.size();
  const std::size_t blocks = (n + kHashBlockRows - 1) / kHashBlockRows;
  std::vector<std::uint64_t> blockHashes(columns.size() * blocks);
  const auto hashBlock = [&](std::size_t t) {
    const std::size_t begin = (t % blocks) * kHashBlockRows;
    blockHashes[t] = columns[t / blocks].hashRows(pool, begin, std::min(n, begin + kHashBlockRows));
  };
  if (n * columns.size() <= kHashBlockRows) {
    for (std::size_t t = 0; t < blockHashes.size(); ++t) hashBlock(t);  // small: no tasks
  } else {
    parallelForTasks(blockHashes.size(), hashBlock);
  }
  std::vector<std::uint64_t> hashes;
  for (std::size_t c = 0; c < columns.size(); ++c) {
    Hasher h;
    h.add(n);
    for (std::size_t b = 0; b < blocks; ++b) h.add(blockHashes[c * blocks + b]);
    hashes.push_back(h.value());
  }
  return hashes;
}

std::uint64_t countersHash(const ParticlePool& pool) {
  Hasher h;
  h.add(pool.size());
  h.add(pool.nextId());
  h.add(pool.droppedSpawns());
  return h.value();
}

// The pool's hash: the chain over its counters, then every column's hash.
void addPool(Hasher& h, const ParticlePool& pool) {
  h.add(pool.size());
  h.add(pool.nextId());
  h.add(pool.droppedSpawns());
  for (const std::uint64_t column : columnHashes(pool)) h.add(column);
}

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

std::vector<std::string> stateColumnNames(const ParticlePool& pool) {
  std::vector<std::string> names = {"counters"};
  for (const HashedColumn& column : hashedColumns(pool)) names.push_back(column.name);
  return names;
}

std::vector<std::uint64_t> stateColumnHashes(const ParticlePool& pool) {
  std::vector<std::uint64_t> hashes = {countersHash(pool)};
  for (const std::uint64_t column : columnHashes(pool)) hashes.push_back(column);
  return hashes;
}

std::vector<std::uint64_t> stateRowBits(const ParticlePool& pool, std::size_t row) {
  std::vector<std::uint64_t> bits = {pool.id()[row],
                                     static_cast<std::uint64_t>(pool.birthTick()[row])};
  for (const HashedColumn& column : hashedColumns(pool)) {
    if (column.kind == HashedColumn::Kind::Id || column.kind == HashedColumn::Kind::BirthTick)
      continue;
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
