// Structure-of-arrays storage for every live particle.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "particles/Column.h"
#include "particles/RelaxedFlag.h"

namespace tickfx {

/// A vector quantity as three component columns: the x values of all particles are contiguous,
/// so a loop over one component vectorises without gathers.
struct Vec3Column {
  FloatColumn x, y, z;

  /// Component c (0 = x, 1 = y, 2 = z), so kernels can loop over components.
  FloatColumn& operator[](int c) { return c == 0 ? x : (c == 1 ? y : z); }
  const FloatColumn& operator[](int c) const { return c == 0 ? x : (c == 1 ? y : z); }

  void resize(Eigen::Index rows);
  void conservativeResize(Eigen::Index rows);
  /// FloatColumn::setRows and dropFront, component by component.
  void setRows(std::size_t rows, std::size_t keep);
  void dropFront(std::size_t k);
  /// Copies rows [begin, end) of `from` into the same rows here, component by component.
  void copyRows(const Vec3Column& from, std::size_t begin, std::size_t end);
};

/// The inverse mass of a particle of `mass` kilograms: 0 for an infinite mass (pinned).
inline float inverseMassOf(float mass) { return std::isinf(mass) ? 0.0f : 1.0f / mass; }

/// Everything a new particle starts with. Units: metres, metres per second, seconds, kilograms.
struct ParticleInit {
  Eigen::Vector3f position = Eigen::Vector3f::Zero();
  Eigen::Vector3f velocity = Eigen::Vector3f::Zero();
  /// Seconds the particle lives; +∞ for never.
  float lifetime = std::numeric_limits<float>::infinity();
  /// Kilograms; +∞ pins the particle (inverse mass 0).
  float mass = 1.0f;
};

/// Where spawned rows' values are written, column by column: pointers to one row of each column a
/// spawn sets (ParticlePool::spawnTargets()); row k of the run is element k of each. Borrowed:
/// valid while the pool's storage stays where it is.
struct SpawnTargets {
  float* position[3];
  float* velocity[3];
  float* lifetime;
  float* mass;
};

/// The particle pool: one column per attribute, rows [0, size()) live, in the order of their ids.
///
/// A tick reads and writes only what it needs: ages are not stored but worked out from the birth
/// tick where they are read (age(), ages()), the inverse mass from the mass (inverseMassOf()), and
/// the scans for expired, pinned and flagged rows run only when a row may be one (the may*()
/// flags, raised by spawns and by any mutable access to the column concerned).
///
/// Ownership: the pool owns all columns. References to columns stay valid; pointers to their
/// values (data()) until the next spawn (which may grow or move the storage) or removeDead()
/// (which moves rows). Spawning appends; deaths are removed by a stable compaction at the end of
/// a tick, so the row order is the id order and the same for any thread count.
///
/// Deaths in place: the rows dead at the front (the oldest particles, the usual deaths of a rate
/// emitter) are dropped by moving each column's start (FloatColumn::dropFront), so they cost no
/// copy; only the rows behind a death further in move. The storage they free is reused by later
/// spawns once it is a quarter of the storage (the live rows are then moved to its front: each
/// row freed pays for at most four moved), else the storage grows.
class ParticlePool {
 public:
  /// `maxParticles` is a hard cap: spawns past it are dropped and counted (droppedSpawns()).
  explicit ParticlePool(std::size_t maxParticles);
  ParticlePool(const ParticlePool&) = default;
  ParticlePool(ParticlePool&&) noexcept = default;
  ParticlePool& operator=(const ParticlePool&) = default;
  ParticlePool& operator=(ParticlePool&&) noexcept = default;
  /// Gives the pages of large columns back in parallel before freeing them: unmapping gigabytes
  /// on one thread takes a tenth of a second a gigabyte.
  ~ParticlePool();

  std::size_t size() const { return size_; }
  std::size_t maxParticles() const { return maxParticles_; }
  /// Spawns refused because the pool was full, since construction.
  std::uint64_t droppedSpawns() const { return droppedSpawns_; }
  /// The id the next spawned particle gets; ids are never reused.
  std::uint64_t nextId() const { return nextId_; }

  /// The last tick a particle can be born in: birth ticks are 32 bits, counted from the run's
  /// start (tick 0), which at 240 ticks a second is 207 days of simulated time. A system refuses
  /// to run past it (ParticleSystem::kMaxTicks).
  static constexpr std::int64_t kMaxBirthTick = std::numeric_limits<std::uint32_t>::max();

  /// Appends a particle born at `tick`; returns its row, or npos when the pool is full.
  std::size_t spawn(const ParticleInit& init, std::int64_t tick);
  static constexpr std::size_t npos = std::numeric_limits<std::size_t>::max();
  /// Appends `count` rows born at `tick` (ids in order, custom attributes at their initial values)
  /// and returns the first; setRow() gives each its values. The caller keeps size() + count within
  /// maxParticles(). With every row set, the same rows, ids and bits as `count` spawn() calls in
  /// order: an emitter fills the rows of a burst in parallel.
  std::size_t appendRows(std::size_t count, std::int64_t tick);
  /// Appends `count` rows born at `tick` whose ids are nextId() + firstOffset + k · stride
  /// (k = 0 .. count − 1), then counts `idsUsed` ids as handed out: a shard's rows of a burst whose
  /// other ids are other shards' (particles/Shard.h). The ids stay rising and below nextId().
  /// appendRows(count, tick) is appendRowsStrided(count, tick, 0, 1, count).
  std::size_t appendRowsStrided(std::size_t count, std::int64_t tick, std::uint64_t firstOffset,
                                std::uint64_t stride, std::uint64_t idsUsed);
  /// Counts `count` ids as handed out to particles this pool does not hold (another shard's).
  void skipIds(std::uint64_t count) { nextId_ += count; }
  /// Gives row `row` (appended, not yet stepped) its particle: position (and previous position),
  /// velocity, lifetime and mass; acceleration (when kept) 0. Different rows may be set at once
  /// from different threads.
  void setRow(std::size_t row, const ParticleInit& init);
  /// setRow() for runs of rows: the caller writes the position, velocity, lifetime and mass of
  /// appended rows [row, row + k) through the pointers, then calls finishRows() on them, which
  /// sets the rest as setRow() does. Different runs may be written at once from different threads.
  SpawnTargets spawnTargets(std::size_t row);
  void finishRows(std::size_t begin, std::size_t end);
  /// Counts `count` spawns refused without trying them (the caller saw the pool was full).
  void refuseSpawns(std::uint64_t count) { droppedSpawns_ += count; }
  /// Takes back the newest rows, [size, size()), and the ids they were given, so that ids from
  /// `nextId` on are handed out again; clears the dead flags of the rows kept. Undoes the spawns
  /// since the pool had `size` rows and `nextId` (a fused frame going back to its start).
  void dropNewest(std::size_t size, std::uint64_t nextId);

  /// Rows [firstUnstepped(), size()) have not been through an integrator step yet (spawned this
  /// tick). Self-starting integrators (position Verlet, velocity Verlet) need to know.
  std::size_t firstUnstepped() const { return firstUnstepped_; }
  void markAllStepped() { firstUnstepped_ = size_; }

  /// Sets the clock the ages refer to: ticks completed and ticks a second. Ages are worked out
  /// from the integer tick count (never accumulated), age = float((tick − birth) · (1/rate)) with
  /// the product in double. Then flags the particles whose age reached their lifetime as dead,
  /// reading the birth ticks and lifetimes only when a row may have a finite lifetime.
  void advanceClock(std::int64_t tick, std::int64_t stepRateHz);
  /// Sets the clock alone, flagging nothing (a restored state, whose expired rows are gone).
  void setClock(std::int64_t tick, std::int64_t stepRateHz);
  /// The clock set by advanceClock() (0 ticks at 60 Hz until then).
  std::int64_t clockTick() const { return clockTick_; }
  std::int64_t stepRateHz() const { return stepRateHz_; }
  /// Age in seconds of row `row` at clockTick().
  float age(std::size_t row) const {
    return ageSeconds(clockTick_ - birthTick_[row], 1.0 / static_cast<double>(stepRateHz_));
  }
  /// The ages of rows [begin, end) into out[0, end − begin): age(row) for each, vectorised.
  void ages(std::size_t begin, std::size_t end, float* out) const;
  /// float(ticks · secondsPerTick) with the product in double, 0 for ticks <= 0 (a row born
  /// at or after the clock's tick: spawned in the tick under way); the integer converted by the
  /// exponent trick (exact below 2^52) because SSE2 has no int64-to-double instruction.
  static float ageSeconds(std::int64_t ticks, double secondsPerTick) {
    const auto lived = static_cast<std::uint64_t>(ticks > 0 ? ticks : 0);
    const double whole = std::bit_cast<double>(lived | 0x4330000000000000ULL) - 0x1p52;
    return static_cast<float>(whole * secondsPerTick);
  }
  /// Removes the particles flagged dead (by a module, or by advanceClock at the end of their
  /// life), keeping the order of the rest. Returns how many were removed. Reads no flag when none
  /// can be set (mayHaveDead()).
  std::size_t removeDead();

  /// Whether some row may have a finite lifetime, be pinned (infinite mass) or be flagged dead.
  /// False means none is: the scans that look for them are skipped. Spawns raise the first two
  /// for what they spawn; a mutable access to lifetime(), mass() or dead() raises its own.
  bool mayHaveFiniteLifetimes() const { return mayExpire_.get(); }
  bool mayHavePinned() const { return mayPin_.get(); }
  bool mayHaveDead() const { return mayDie_.get(); }
  /// Whether any of rows [0, size()) is pinned (inverse mass 0): a scan when mayHavePinned(),
  /// which clears that flag when it finds none.
  bool anyPinned() const;
  /// Applies to `column` (a caller's copy, rows matching the pool's) the removal removeDead()
  /// is about to make, so the copy keeps matching the rows after it.
  void applyRemovalTo(Vec3Column& column) const;

  // Columns. Storage may be longer than size(); only rows [0, size()) are meaningful.
  Vec3Column& position() { return position_; }
  Vec3Column& velocity() { return velocity_; }
  /// Position at the start of the newest tick that kept it: for interpolating a frame between
  /// two ticks, and position Verlet's history (its state). The column exists only once
  /// keepPrevious() was called (holding no rows until then); a tick writes it only when a frame
  /// interpolates across that tick (StepRows::keepPrevious), colliders follow paths from it, or
  /// it is state.
  Vec3Column& previousPosition() { return previous_; }
  /// Gives the pool its previous-position column, every row's value its position, if it has none
  /// yet; `asState` (position Verlet) makes it state from now on: written by every tick and
  /// covered by the state hash.
  void keepPrevious(bool asState = false);
  bool keepsPrevious() const { return keepsPrevious_; }
  bool previousIsState() const { return previousIsState_; }
  /// Acceleration at the current state, kept by velocity Verlet between ticks (m/s²). The column
  /// exists only once keepAcceleration() was called (velocity Verlet does); until then it holds
  /// no rows, and the state has 0 there (the state hash and checkpoints count it as zeros).
  Vec3Column& acceleration() { return acceleration_; }
  /// Gives the pool its acceleration column, every row 0, if it has none yet.
  void keepAcceleration();
  bool keepsAcceleration() const { return keepsAcceleration_; }
  /// Seconds the particle lives (+∞: never). Mutable access counts as writing a finite one.
  FloatColumn& lifetime() {
    mayExpire_.raise();
    forgetLifetimeFloor();
    return lifetime_;
  }
  /// Kilograms (+∞: pinned). Mutable access counts as writing an infinite one.
  FloatColumn& mass() {
    mayPin_.raise();
    return mass_;
  }
  RowColumn<std::uint64_t>& id() { return id_; }
  /// The tick each particle was born in (0 to kMaxBirthTick). Mutable access counts as writing
  /// births out of row order.
  RowColumn<std::uint32_t>& birthTick() {
    birthsInOrder_ = false;
    return birthTick_;
  }
  /// Nonzero marks a particle for removal at the end of the tick (written by force modules that
  /// kill, each for its own rows only). Mutable access counts as flagging one.
  RowColumn<std::uint8_t>& dead() {
    mayDie_.raise();
    mayDieAnywhere_.raise();
    return dead_;
  }

  const Vec3Column& position() const { return position_; }
  const Vec3Column& velocity() const { return velocity_; }
  const Vec3Column& previousPosition() const { return previous_; }
  const Vec3Column& acceleration() const { return acceleration_; }
  const FloatColumn& lifetime() const { return lifetime_; }
  const FloatColumn& mass() const { return mass_; }
  const RowColumn<std::uint64_t>& id() const { return id_; }
  const RowColumn<std::uint32_t>& birthTick() const { return birthTick_; }
  const RowColumn<std::uint8_t>& dead() const { return dead_; }

  /// Adds a named float attribute, every row set to `initial` (new particles get it too).
  /// Returns its index; adding an existing name returns the existing index.
  std::size_t addAttribute(const std::string& name, float initial = 0.0f);
  /// Index of the attribute `name`, or npos.
  std::size_t findAttribute(const std::string& name) const;
  std::size_t attributeCount() const { return attributes_.size(); }
  const std::string& attributeName(std::size_t index) const { return attributes_[index].name; }
  FloatColumn& attribute(std::size_t index) { return attributes_[index].values; }
  const FloatColumn& attribute(std::size_t index) const { return attributes_[index].values; }

  /// Changes whenever rows already in the pool may have moved or been replaced (a removal that
  /// removed something, a restore); appending rows keeps it. A module that keeps tables by row
  /// (springs) rebuilds them only when it changed.
  std::uint64_t rowsVersion() const { return rowsVersion_; }

  /// Rows the columns currently hold from row 0 on (>= size()); grows geometrically, never past
  /// maxParticles.
  std::size_t storageRows() const { return storageRows_; }
  /// Rows the columns' storage holds in all: storageRows() and the rows dropped at the front
  /// since the storage last moved (reused by later spawns). Memory is allocatedRows() ·
  /// bytesPerRow() bytes.
  std::size_t allocatedRows() const { return storageRows_ + frontRows_; }
  /// Bytes a row takes over every column, the named attributes included: the pool's columns hold
  /// allocatedRows() · bytesPerRow() bytes.
  std::size_t bytesPerRow() const;
  /// Makes room for `rows` rows without changing size() (for restoring a saved state).
  void reserve(std::size_t rows);
  /// Sets size() directly (throws std::invalid_argument past maxParticles) and clears the dead
  /// flags; the caller then writes every column of rows [0, size) (restoring a saved state).
  void resizeForRestore(std::size_t size, std::uint64_t nextId, std::uint64_t droppedSpawns);
  /// Why rows with these ids and birth ticks are not a state a pool reaches by tick `tick` with
  /// `nextId` ids handed out (ids strictly rising, below nextId; births in [0, tick]), or
  /// nothing when they are one. For saved states, before anything is restored.
  static std::optional<std::string> restoreProblem(std::span<const std::uint64_t> ids,
                                                   std::span<const std::uint32_t> births,
                                                   std::uint64_t nextId, std::int64_t tick);

 private:
  struct NamedColumn {
    std::string name;
    float initial = 0.0f;
    FloatColumn values;
  };

  // Room for `rows` rows from row 0: the freed front reused, or the storage grown.
  void makeRoom(std::size_t rows);
  // Every column holds `rows` rows from row 0 on, the live ones kept.
  void setStorageRows(std::size_t rows);
  // Drops the first `count` rows of every column (dead at the front), in O(1).
  void dropFront(std::size_t count);
  template <class Visit>
  void forEachColumn(const Visit& visit);
  // Rows [0, end) hold every flag: the rows advanceClock() tested, or all after a mutable dead().
  std::size_t flaggedRowsEnd() const {
    return mayDieAnywhere_.get() ? size_ : std::min(expiredRowsEnd_, size_);
  }
  // The rows advanceClock() must test: [0, end), every row past it younger than the lifetime
  // floor, so alive.
  std::size_t rowsThatMayExpire(std::int64_t tick, double secondsPerTick);
  void forgetLifetimeFloor() {
    lifetimeFloor_ = std::numeric_limits<float>::infinity();
    floorRows_ = 0;
  }

  std::size_t maxParticles_;
  std::size_t size_ = 0;
  std::size_t storageRows_ = 0;
  std::size_t frontRows_ = 0;  // dropped at the front of the storage, not yet reused
  std::size_t firstUnstepped_ = 0;
  std::uint64_t nextId_ = 0;
  std::uint64_t droppedSpawns_ = 0;
  std::uint64_t rowsVersion_ = 0;
  bool keepsAcceleration_ = false;
  bool keepsPrevious_ = false;
  bool previousIsState_ = false;
  std::int64_t clockTick_ = 0;
  std::int64_t stepRateHz_ = 60;
  RelaxedFlag mayExpire_, mayDie_;
  RelaxedFlag mayDieAnywhere_;      // raised by dead(): a flag may be in any row
  std::size_t expiredRowsEnd_ = 0;  // advanceClock() flagged rows below this only
  // No lifetime of rows [0, floorRows_) is below lifetimeFloor_ (rows removed since only raise
  // the true minimum; the rows appended since are covered at the next advanceClock()).
  float lifetimeFloor_ = std::numeric_limits<float>::infinity();
  std::size_t floorRows_ = 0;
  // Birth ticks never fall from row to row (spawns append at the clock's tick): then ages never
  // rise from row to row, and the rows old enough to expire are a prefix.
  bool birthsInOrder_ = true;
  mutable RelaxedFlag mayPin_;  // cleared by a const scan that found nothing

  Vec3Column position_, velocity_, previous_, acceleration_;
  FloatColumn lifetime_, mass_;
  RowColumn<std::uint64_t> id_;
  RowColumn<std::uint32_t> birthTick_;
  RowColumn<std::uint8_t> dead_;
  std::vector<NamedColumn> attributes_;
};

}  // namespace tickfx
