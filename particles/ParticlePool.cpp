#include "particles/ParticlePool.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "particles/Assert.h"
#include "particles/ParallelFor.h"
#include "particles/PhaseProfile.h"

#if defined(__linux__)
#include <sys/mman.h>
#include <unistd.h>
#endif

namespace tickfx {
namespace {

// A run of kept rows and where the removal moves it: rows [from, from + count) to `to` (to <=
// from). Applied in order, a run's move never overwrites a later run's rows.
struct KeptRun {
  std::size_t from, count, to;
};

// The first flagged row in [from, size), or size. Eight flags at a time: deaths are rare, or come
// in runs (the oldest particles of a rate emitter die together), so the clear stretches are long.
std::size_t firstFlagged(const std::uint8_t* flags, std::size_t from, std::size_t size) {
  std::size_t i = from;
  for (std::uint64_t word = 0; i + 8 <= size; i += 8) {
    std::memcpy(&word, flags + i, sizeof word);
    if (word != 0) break;
  }
  while (i < size && flags[i] == 0) ++i;
  return i;
}

// The runs of kept rows in [first, size), rows before `first` staying where they are.
std::vector<KeptRun> keptRuns(const std::uint8_t* flags, std::size_t first, std::size_t size) {
  std::vector<KeptRun> runs;
  std::size_t to = first;
  std::size_t i = first;
  while (i < size) {
    while (i < size && flags[i] != 0) ++i;  // removed rows
    const std::size_t from = i;
    i = firstFlagged(flags, i, size);
    if (i > from) {
      runs.push_back(KeptRun{from, i - from, to});
      to += i - from;
    }
  }
  return runs;
}

// The number of rows flagged at the front, [0, lead).
std::size_t leadingFlagged(const std::uint8_t* flags, std::size_t size) {
  std::size_t i = 0;
  while (i < size && flags[i] != 0) ++i;
  return i;
}

// Moves each run of a column of T: memmove for long runs (a whole column is one or a few when
// deaths come together, where a row-by-row copy behind a flag test ran at a fraction of memory
// speed), a plain loop for short ones (deaths scattered by lifetime jitter).
template <typename T>
void moveRuns(T* column, const std::vector<KeptRun>& runs) {
  for (const KeptRun& r : runs) {
    if (r.from == r.to) continue;
    if (r.count >= 16) {
      std::memmove(column + r.to, column + r.from, r.count * sizeof(T));
    } else {
      for (std::size_t k = 0; k < r.count; ++k) column[r.to + k] = column[r.from + k];
    }
  }
}

}  // namespace

void Vec3Column::resize(Eigen::Index rows) {
  x.resize(rows);
  y.resize(rows);
  z.resize(rows);
}

void Vec3Column::conservativeResize(Eigen::Index rows) {
  x.conservativeResize(rows);
  y.conservativeResize(rows);
  z.conservativeResize(rows);
}

void Vec3Column::setRows(std::size_t rows, std::size_t keep) {
  for (int c = 0; c < 3; ++c) (*this)[c].setRows(rows, keep);
}

void Vec3Column::dropFront(std::size_t k) {
  for (int c = 0; c < 3; ++c) (*this)[c].dropFront(k);
}

void Vec3Column::copyRows(const Vec3Column& from, std::size_t begin, std::size_t end) {
  const auto i = static_cast<Eigen::Index>(begin), n = static_cast<Eigen::Index>(end - begin);
  for (int c = 0; c < 3; ++c) (*this)[c].segment(i, n) = from[c].segment(i, n);
}

ParticlePool::ParticlePool(std::size_t maxParticles) : maxParticles_(maxParticles) {
  if (maxParticles >= (std::size_t{1} << 32)) {
    // Row indices are 32-bit in the compaction and in the spring tables.
    maxParticles_ = (std::size_t{1} << 32) - 1;
  }
}

void ParticlePool::reserve(std::size_t rows) {
  if (rows > storageRows_) setStorageRows(std::max(storageRows_, std::min(rows, maxParticles_)));
}

std::size_t ParticlePool::bytesPerRow() const {
  constexpr std::size_t kVec3 = 3 * sizeof(float);
  const int vectors = 2 + (keepsPrevious_ ? 1 : 0) + (keepsAcceleration_ ? 1 : 0);
  return static_cast<std::size_t>(vectors) * kVec3 + 2 * sizeof(float) + sizeof(std::uint64_t) +
         sizeof(std::uint32_t) + sizeof(std::uint8_t) + attributes_.size() * sizeof(float);
}

void ParticlePool::keepAcceleration() {
  if (keepsAcceleration_) return;
  acceleration_.resize(static_cast<Eigen::Index>(storageRows_));
  for (int c = 0; c < 3; ++c) acceleration_[c].setZero();
  keepsAcceleration_ = true;
}

void ParticlePool::keepPrevious(bool asState) {
  previousIsState_ = previousIsState_ || asState;
  if (keepsPrevious_) return;
  previous_.resize(static_cast<Eigen::Index>(storageRows_));
  // The live rows start where they are; the rows past them are written when spawned.
  previous_.copyRows(position_, 0, size_);
  keepsPrevious_ = true;
}

template <class Visit>
void ParticlePool::forEachColumn(const Visit& visit) {
  for (Vec3Column* v : {&position_, &velocity_, &previous_, &acceleration_}) {
    if ((v == &acceleration_ && !keepsAcceleration_) || (v == &previous_ && !keepsPrevious_))
      continue;
    for (int k = 0; k < 3; ++k) visit((*v)[k]);
  }
  for (FloatColumn* c : {&lifetime_, &mass_}) visit(*c);
  for (NamedColumn& a : attributes_) visit(a.values);
  visit(id_);
  visit(birthTick_);
  visit(dead_);
}

ParticlePool::~ParticlePool() {
  // Each column's pages, in chunks of 16 MiB, handed back to the kernel by parallel tasks
  // (madvise(MADV_DONTNEED)): the free() that follows then unmaps no page. Only whole pages inside
  // each column's live rows are released, and only of columns of two chunks or more, which every
  // allocator maps on their own: the memory is about to be freed, so what it reads afterwards
  // does not matter.
#if defined(__linux__)
  constexpr std::size_t kChunk = std::size_t{16} << 20;
  const auto page = static_cast<std::uintptr_t>(sysconf(_SC_PAGESIZE));
  std::vector<std::pair<std::uintptr_t, std::size_t>> chunks;
  forEachColumn([&](auto& column) {
    // The column's own row count: a moved-from pool's columns are empty.
    const std::size_t bytes = static_cast<std::size_t>(column.size()) * sizeof(*column.data());
    if (page == 0 || column.data() == nullptr || bytes < 2 * kChunk) return;
    const auto start = reinterpret_cast<std::uintptr_t>(column.data());
    const std::uintptr_t begin = (start + page - 1) / page * page;
    const std::uintptr_t end = (start + bytes) / page * page;
    for (std::uintptr_t c = begin; c < end; c += kChunk)
      chunks.emplace_back(c, std::min(kChunk, end - c));
  });
  parallelForTasks(chunks.size(), [&](std::size_t i) {
    ::madvise(reinterpret_cast<void*>(chunks[i].first), chunks[i].second, MADV_DONTNEED);
  });
#endif
}

void ParticlePool::setStorageRows(std::size_t rows) {
  const profile::PhaseScope phase(profile::Phase::Growth);
  TICKFX_ASSERT(rows >= size_, "storage shorter than the live rows");
  // Columns are independent: each is a task (a move of the live rows at most).
  std::vector<FloatColumn*> floats;
  forEachColumn([&](auto& column) {
    if constexpr (std::is_same_v<std::decay_t<decltype(column)>, FloatColumn>)
      floats.push_back(&column);
  });
  parallelForTasks(floats.size() + 3, [&](std::size_t c) {
    if (c < floats.size()) {
      floats[c]->setRows(rows, size_);
    } else if (c == floats.size()) {
      id_.setRows(rows, size_);
    } else if (c == floats.size() + 1) {
      birthTick_.setRows(rows, size_);
    } else {
      dead_.setRows(rows, size_);
    }
  });
  storageRows_ = rows;
  frontRows_ = 0;
}

void ParticlePool::makeRoom(std::size_t rows) {
  if (rows <= storageRows_) return;
  const std::size_t capacity = storageRows_ + frontRows_;
  // The freed front is reused once it is a quarter of the storage (or the storage is as large as
  // it may be): moving the live rows to the front then costs at most four rows moved per row
  // freed since the storage last moved.
  if (rows <= capacity && frontRows_ > 0 &&
      (4 * frontRows_ >= capacity || capacity >= maxParticles_)) {
    setStorageRows(capacity);
    return;
  }
  // Geometric growth as one spawn at a time would make it, or room for the whole burst.
  const std::size_t doubled = std::max<std::size_t>(1024, capacity * 2);
  setStorageRows(std::min(maxParticles_, std::max(doubled, rows)));
}

void ParticlePool::dropFront(std::size_t count) {
  forEachColumn([count](auto& column) { column.dropFront(count); });
  size_ -= count;
  storageRows_ -= count;
  frontRows_ += count;
}

std::size_t ParticlePool::spawn(const ParticleInit& init, std::int64_t tick) {
  if (size_ >= maxParticles_) {
    ++droppedSpawns_;
    return npos;
  }
  const std::size_t i = appendRows(1, tick);
  setRow(i, init);
  return i;
}

std::size_t ParticlePool::appendRows(std::size_t count, std::int64_t tick) {
  return appendRowsStrided(count, tick, 0, 1, count);
}

std::size_t ParticlePool::appendRowsStrided(std::size_t count, std::int64_t tick,
                                            std::uint64_t firstOffset, std::uint64_t stride,
                                            std::uint64_t idsUsed) {
  TICKFX_ASSERT(count <= maxParticles_ - size_, "rows appended past maxParticles");
  TICKFX_ASSERT(tick >= 0 && tick <= kMaxBirthTick, "a birth tick past 32 bits");
  TICKFX_ASSERT(stride >= 1 && (count == 0 || firstOffset + (count - 1) * stride < idsUsed),
                "strided ids past the ids handed out");
  const std::size_t first = size_;
  if (first > 0 && birthTick_[first - 1] > tick) birthsInOrder_ = false;
  makeRoom(first + count);
  size_ += count;
  TICKFX_ASSERT(size_ <= storageRows_, "rows appended past the pool's storage");
  // New rows are first written here, by the threads of the blocks (first touch: a burst's pages
  // are faulted in by every thread, not one).
  const std::uint64_t firstId = nextId_ + firstOffset;
  const auto fill = [&](std::size_t begin, std::size_t end) {
    // Through restrict pointers, one column at a time: loops that vectorise.
    std::uint64_t* __restrict ids = id_.data() + first;
    std::uint32_t* __restrict births = birthTick_.data() + first;
    std::uint64_t id = firstId + begin * stride;
    for (std::size_t i = begin; i < end; ++i, id += stride) ids[i] = id;
    std::fill(births + begin, births + end, static_cast<std::uint32_t>(tick));
    std::uint8_t* dead = dead_.data() + first;
    std::fill(dead + begin, dead + end, std::uint8_t{0});  // (memset's pointer may not be null)
    const auto head = static_cast<Eigen::Index>(first + begin);
    const auto n = static_cast<Eigen::Index>(end - begin);
    for (NamedColumn& a : attributes_) a.values.segment(head, n).setConstant(a.initial);
  };
  if (count <= kParallelBlockRows) {
    fill(0, count);  // one spawn, or a few: no task to make
  } else {
    parallelForRows(count, fill);
  }
  nextId_ += idsUsed;
  return first;
}

void ParticlePool::setRow(std::size_t row, const ParticleInit& init) {
  TICKFX_ASSERT(row < size_, "a row set past the pool's size");
  const SpawnTargets to = spawnTargets(row);
  for (int c = 0; c < 3; ++c) {
    *to.position[c] = init.position[c];
    *to.velocity[c] = init.velocity[c];
  }
  *to.lifetime = init.lifetime;
  *to.mass = init.mass;
  finishRows(row, row + 1);
}

SpawnTargets ParticlePool::spawnTargets(std::size_t row) {
  TICKFX_ASSERT(row <= size_, "spawn targets past the pool's size");
  return {{position_.x.data() + row, position_.y.data() + row, position_.z.data() + row},
          {velocity_.x.data() + row, velocity_.y.data() + row, velocity_.z.data() + row},
          lifetime_.data() + row,
          mass_.data() + row};
}

void ParticlePool::finishRows(std::size_t begin, std::size_t end) {
  TICKFX_ASSERT(begin <= end && end <= size_, "finished rows past the pool's size");
  const auto head = static_cast<Eigen::Index>(begin);
  const auto n = static_cast<Eigen::Index>(end - begin);
  if (keepsPrevious_) {
    for (int c = 0; c < 3; ++c) previous_[c].segment(head, n) = position_[c].segment(head, n);
  }
  if (keepsAcceleration_) {
    for (int c = 0; c < 3; ++c) acceleration_[c].segment(head, n).setZero();
  }
  // The flags setRow() raises, from one pass over each column: infinities told by their bits
  // (exponent all ones, mantissa zero), in a loop with no branch that vectorises.
  const auto* life = reinterpret_cast<const std::uint32_t*>(lifetime_.data());
  const auto* mass = reinterpret_cast<const std::uint32_t*>(mass_.data());
  constexpr std::uint32_t kMagnitude = 0x7fffffffU, kInfinity = 0x7f800000U;
  std::uint32_t finite = 0, pinned = 0;
  for (std::size_t i = begin; i < end; ++i) {
    finite |= static_cast<std::uint32_t>((life[i] & kMagnitude) != kInfinity);
    pinned |= static_cast<std::uint32_t>((mass[i] & kMagnitude) == kInfinity);
  }
  if (finite != 0) mayExpire_.raise();
  if (pinned != 0) mayPin_.raise();
}

std::optional<std::string> ParticlePool::restoreProblem(std::span<const std::uint64_t> ids,
                                                        std::span<const std::uint32_t> births,
                                                        std::uint64_t nextId, std::int64_t tick) {
  for (std::size_t i = 0; i < ids.size(); ++i) {
    if (ids[i] >= nextId || (i > 0 && ids[i] <= ids[i - 1])) {
      return "row " + std::to_string(i) + " has id " + std::to_string(ids[i]) +
             " (ids rise from row to row and stay below the next id, " + std::to_string(nextId) +
             ")";
    }
  }
  if (tick > kMaxBirthTick + 1) {
    return "tick " + std::to_string(tick) + " is past the last a run can have (" +
           std::to_string(kMaxBirthTick + 1) + ": birth ticks are 32 bits)";
  }
  for (std::size_t i = 0; i < births.size(); ++i) {
    if (births[i] > tick) {
      return "row " + std::to_string(i) + " was born at tick " + std::to_string(births[i]) +
             " (expected 0 to " + std::to_string(tick) + ")";
    }
  }
  return std::nullopt;
}

void ParticlePool::ages(std::size_t begin, std::size_t end, float* out) const {
  // A product with the reciprocal rather than a division per row: the loop vectorises.
  const double secondsPerTick = 1.0 / static_cast<double>(stepRateHz_);
  const std::uint32_t* birth = birthTick_.data();
  const std::int64_t tick = clockTick_;
  for (std::size_t i = begin; i < end; ++i)
    out[i - begin] = ageSeconds(tick - birth[i], secondsPerTick);
}

void ParticlePool::setClock(std::int64_t tick, std::int64_t stepRateHz) {
  TICKFX_ASSERT(stepRateHz > 0, "a clock of no ticks a second");
  clockTick_ = tick;
  stepRateHz_ = stepRateHz;
}

std::size_t ParticlePool::rowsThatMayExpire(std::int64_t tick, double secondsPerTick) {
  if (!birthsInOrder_) {
    // Written from outside (a restored state): find out once whether they are in order.
    birthsInOrder_ = std::is_sorted(birthTick_.begin(), birthTick_.begin() + size_);
    if (!birthsInOrder_) return size_;
  }
  if (floorRows_ < size_) {
    // The rows appended since the last tick (or all, after a mutable access): a minimum, the same
    // in any order of its terms (lifetimes are never NaN), so each block takes its own in
    // parallel and the blocks' minima are taken after.
    const float* life = lifetime_.data() + floorRows_;
    const std::size_t rows = size_ - floorRows_;
    std::vector<float> floors((rows + kParallelBlockRows - 1) / kParallelBlockRows);
    parallelForRows(rows, [&](std::size_t b, std::size_t e) {
      float floor = std::numeric_limits<float>::infinity();
      for (std::size_t i = b; i < e; ++i) floor = life[i] < floor ? life[i] : floor;
      floors[b / kParallelBlockRows] = floor;
    });
    for (const float floor : floors)
      lifetimeFloor_ = floor < lifetimeFloor_ ? floor : lifetimeFloor_;
    floorRows_ = size_;
  }
  // Ages fall (weakly) from row to row: the rows whose age reached the floor are a prefix,
  // found by bisection with the expression the scan compares.
  const std::uint32_t* birth = birthTick_.data();
  std::size_t lo = 0, hi = size_;
  while (lo < hi) {
    const std::size_t mid = lo + (hi - lo) / 2;
    if (ageSeconds(tick - birth[mid], secondsPerTick) >= lifetimeFloor_) {
      lo = mid + 1;
    } else {
      hi = mid;
    }
  }
  return lo;
}

void ParticlePool::advanceClock(std::int64_t tick, std::int64_t stepRateHz) {
  setClock(tick, stepRateHz);
  if (!mayExpire_.get()) return;
  const double secondsPerTick = 1.0 / static_cast<double>(stepRateHz);
  const std::uint32_t* birth = birthTick_.data();
  const float* life = lifetime_.data();
  std::uint8_t* dead = dead_.data();
  const std::size_t end = rowsThatMayExpire(tick, secondsPerTick);
  if (birthsInOrder_ && floorRows_ == size_ &&
      lifetimeFloor_ == std::numeric_limits<float>::infinity()) {
    mayExpire_.clear();  // no row has a finite lifetime
    return;
  }
  // Whether any row has a finite lifetime: when none has, the next ticks skip this scan.
  RelaxedFlag finite, expired;
  if (end < size_) finite.raise();  // the rows past `end` were not read: assume one has
  parallelForRows(end, [&](std::size_t b, std::size_t e) {
    // Ages in registers, compared and dropped: a vectorised test first, the byte flags only for
    // a block where some particle died (rare, or a run at the front).
    int anyExpired = 0, anyFinite = 0;
    for (std::size_t i = b; i < e; ++i) {
      anyExpired |= static_cast<int>(ageSeconds(tick - birth[i], secondsPerTick) >= life[i]);
      anyFinite |= static_cast<int>(life[i] < std::numeric_limits<float>::infinity());
    }
    if (anyFinite != 0) finite.raise();
    if (anyExpired == 0) return;
    expired.raise();
    for (std::size_t i = b; i < e; ++i) {
      const bool over = ageSeconds(tick - birth[i], secondsPerTick) >= life[i];
      dead[i] = static_cast<std::uint8_t>(dead[i] | (over ? 1 : 0));
    }
  });
  if (expired.get()) {
    mayDie_.raise();
    expiredRowsEnd_ = std::max(expiredRowsEnd_, end);
  }
  if (!finite.get()) mayExpire_.clear();
}

bool ParticlePool::anyPinned() const {
  if (!mayPin_.get()) return false;
  // In parallel blocks, each a branch-free loop the compiler vectorises.
  const float* m = mass_.data();
  RelaxedFlag found;
  parallelForRows(size_, [&](std::size_t b, std::size_t e) {
    int pinned = 0;
    for (std::size_t i = b; i < e; ++i)
      pinned |= static_cast<int>(std::fabs(m[i]) == std::numeric_limits<float>::infinity());
    if (pinned != 0) found.raise();
  });
  if (!found.get()) mayPin_.clear();
  return found.get();
}

namespace {

// keptRuns() of rows [first, size) when no row from `end` on is flagged (only [first, end) read).
std::vector<KeptRun> keptRunsBelow(const std::uint8_t* flags, std::size_t first, std::size_t end,
                                   std::size_t size) {
  std::vector<KeptRun> runs = keptRuns(flags, first, end);
  if (end < size) {
    if (!runs.empty() && runs.back().from + runs.back().count == end) {
      runs.back().count += size - end;
    } else {
      const std::size_t to = runs.empty() ? first : runs.back().to + runs.back().count;
      runs.push_back(KeptRun{end, size - end, to});
    }
  }
  return runs;
}

}  // namespace

std::size_t ParticlePool::removeDead() {
  // Most ticks nobody dies: find that out with no scan when nothing can have flagged a row, else
  // with one byte scan, and touch nothing else.
  if (!mayDie_.get()) return 0;
  mayDie_.clear();
  std::size_t end = flaggedRowsEnd();
  mayDieAnywhere_.clear();
  expiredRowsEnd_ = 0;
  std::size_t first = firstFlagged(dead_.data(), 0, end);
  if (first == end) return 0;
  const std::size_t before = size_;
  if (first == 0) {
    // The dead at the front go with no copy; the scan below starts at the first one kept.
    const std::size_t lead = leadingFlagged(dead_.data(), end);
    dropFront(lead);
    end -= lead;
    first = firstFlagged(dead_.data(), 0, end);
  }
  if (first < end) {
    const std::vector<KeptRun> runs = keptRunsBelow(dead_.data(), first, end, size_);
    // Columns are independent: each is a task, moved whole (bytes only, nothing to reorder).
    std::vector<float*> floats;
    forEachColumn([&](auto& column) {
      if constexpr (std::is_same_v<std::decay_t<decltype(column)>, FloatColumn>)
        floats.push_back(column.data());
    });
    parallelForTasks(floats.size() + 2, [&](std::size_t c) {
      if (c < floats.size()) {
        moveRuns(floats[c], runs);
      } else if (c == floats.size()) {
        moveRuns(id_.data(), runs);
      } else {
        moveRuns(birthTick_.data(), runs);
      }
    });
    const std::size_t kept = runs.empty() ? first : runs.back().to + runs.back().count;
    std::fill(dead_.begin() + first, dead_.begin() + end, std::uint8_t{0});
    size_ = kept;
  }
  ++rowsVersion_;
  firstUnstepped_ = std::min(firstUnstepped_, size_);
  // The survivors of the rows the lifetime floor covered are still the first rows, all but at
  // most the removed count of them.
  floorRows_ -= std::min(floorRows_, before - size_);
  return before - size_;
}

void ParticlePool::dropNewest(std::size_t size, std::uint64_t nextId) {
  TICKFX_ASSERT(size <= size_ && nextId <= nextId_ && nextId_ - nextId == size_ - size,
                "dropping rows that were not the newest spawns");
  size_ = size;
  nextId_ = nextId;
  floorRows_ = std::min(floorRows_, size_);
  ++rowsVersion_;
  std::fill(dead_.begin(), dead_.begin() + size_, std::uint8_t{0});
  firstUnstepped_ = std::min(firstUnstepped_, size_);
}

void ParticlePool::applyRemovalTo(Vec3Column& column) const {
  TICKFX_ASSERT(static_cast<std::size_t>(column.x.size()) >= size_,
                "a column shorter than the pool it follows");
  if (!mayDie_.get()) return;
  const std::size_t end = flaggedRowsEnd();
  const std::size_t first = firstFlagged(dead_.data(), 0, end);
  if (first == end) return;
  // As removeDead(): the dead at the front dropped, the rest compacted.
  const std::size_t lead = first == 0 ? leadingFlagged(dead_.data(), end) : 0;
  column.dropFront(lead);
  const std::uint8_t* flags = dead_.data() + lead;
  const std::size_t next = firstFlagged(flags, 0, end - lead);
  if (next == end - lead) return;
  const std::vector<KeptRun> runs = keptRunsBelow(flags, next, end - lead, size_ - lead);
  for (int k = 0; k < 3; ++k) moveRuns(column[k].data(), runs);
}

std::size_t ParticlePool::addAttribute(const std::string& name, float initial) {
  const std::size_t existing = findAttribute(name);
  if (existing != npos) return existing;
  NamedColumn column{name, initial,
                     FloatColumn::Constant(static_cast<Eigen::Index>(storageRows_), initial)};
  attributes_.push_back(std::move(column));
  return attributes_.size() - 1;
}

std::size_t ParticlePool::findAttribute(const std::string& name) const {
  for (std::size_t i = 0; i < attributes_.size(); ++i) {
    if (attributes_[i].name == name) return i;
  }
  return npos;
}

void ParticlePool::resizeForRestore(std::size_t size, std::uint64_t nextId,
                                    std::uint64_t droppedSpawns) {
  if (size > maxParticles_) {
    throw std::invalid_argument("restored particle count " + std::to_string(size) +
                                " exceeds max_particles " + std::to_string(maxParticles_));
  }
  reserve(size);
  size_ = size;
  forgetLifetimeFloor();
  birthsInOrder_ = false;  // the caller writes them
  ++rowsVersion_;
  std::fill(dead_.begin(), dead_.begin() + size_, std::uint8_t{0});
  firstUnstepped_ = size_;
  nextId_ = nextId;
  droppedSpawns_ = droppedSpawns;
}

}  // namespace tickfx
