// Structure-of-arrays storage for every live particle.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace tickfx {

/// One float per particle. Eigen's allocator aligns the storage for SIMD loads.
using FloatColumn = Eigen::ArrayXf;

/// A vector quantity as three component columns: the x values of all particles are contiguous,
/// so a loop over one component vectorises without gathers.
struct Vec3Column {
  FloatColumn x, y, z;

  /// Component c (0 = x, 1 = y, 2 = z), so kernels can loop over components.
  FloatColumn& operator[](int c) { return c == 0 ? x : (c == 1 ? y : z); }
  const FloatColumn& operator[](int c) const { return c == 0 ? x : (c == 1 ? y : z); }

  void resize(Eigen::Index rows);
  void conservativeResize(Eigen::Index rows);
  /// Copies rows [begin, end) of `from` into the same rows here, component by component.
  void copyRows(const Vec3Column& from, std::size_t begin, std::size_t end);
};

/// Everything a new particle starts with. Units: metres, metres per second, seconds, kilograms.
struct ParticleInit {
  Eigen::Vector3f position = Eigen::Vector3f::Zero();
  Eigen::Vector3f velocity = Eigen::Vector3f::Zero();
  /// Seconds the particle lives; +∞ for never.
  float lifetime = std::numeric_limits<float>::infinity();
  /// Kilograms; +∞ pins the particle (inverse mass 0).
  float mass = 1.0f;
};

/// The particle pool: one column per attribute, rows [0, size()) live, in the order of their ids.
///
/// Ownership: the pool owns all columns. References to columns stay valid until the next spawn
/// (which may grow the storage) or removeDead() (which moves rows). Spawning appends; deaths are
/// removed by a stable compaction at the end of a tick, so the row order is the id order and the
/// same for any thread count.
class ParticlePool {
 public:
  /// `maxParticles` is a hard cap: spawns past it are dropped and counted (droppedSpawns()).
  explicit ParticlePool(std::size_t maxParticles);

  std::size_t size() const { return size_; }
  std::size_t maxParticles() const { return maxParticles_; }
  /// Spawns refused because the pool was full, since construction.
  std::uint64_t droppedSpawns() const { return droppedSpawns_; }
  /// The id the next spawned particle gets; ids are never reused.
  std::uint64_t nextId() const { return nextId_; }

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
  /// velocity, lifetime and mass; acceleration (when kept) and age 0. Different rows may be set at
  /// once from different threads.
  void setRow(std::size_t row, const ParticleInit& init);
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

  /// Recomputes every age from the integer tick count (never accumulated),
  /// age = float((tick − birth) · (1/rate)) with the product in double, and flags the particles
  /// whose age reached their lifetime as dead.
  void updateAges(std::int64_t tick, std::int64_t stepRateHz);
  /// Removes the particles flagged dead (by a module, or by updateAges at the end of their
  /// life), keeping the order of the rest. Returns how many were removed.
  std::size_t removeDead();
  /// Applies to `column` (a caller's copy, rows matching the pool's) the removal removeDead()
  /// is about to make, so the copy keeps matching the rows after it.
  void applyRemovalTo(Vec3Column& column) const;

  // Columns. Storage may be longer than size(); only rows [0, size()) are meaningful.
  Vec3Column& position() { return position_; }
  Vec3Column& velocity() { return velocity_; }
  /// Position at the previous tick (for interpolation, and position Verlet's history).
  Vec3Column& previousPosition() { return previous_; }
  /// Acceleration at the current state, kept by velocity Verlet between ticks (m/s²). The column
  /// exists only once keepAcceleration() was called (velocity Verlet does); until then it holds
  /// no rows, and the state has 0 there (the state hash and checkpoints count it as zeros).
  Vec3Column& acceleration() { return acceleration_; }
  /// Gives the pool its acceleration column, every row 0, if it has none yet.
  void keepAcceleration();
  bool keepsAcceleration() const { return keepsAcceleration_; }
  FloatColumn& age() { return age_; }
  FloatColumn& lifetime() { return lifetime_; }
  FloatColumn& mass() { return mass_; }
  FloatColumn& inverseMass() { return inverseMass_; }
  std::vector<std::uint64_t>& id() { return id_; }
  std::vector<std::int64_t>& birthTick() { return birthTick_; }
  /// Nonzero marks a particle for removal at the end of the tick (written by force modules that
  /// kill, each for its own rows only).
  std::vector<std::uint8_t>& dead() { return dead_; }

  const Vec3Column& position() const { return position_; }
  const Vec3Column& velocity() const { return velocity_; }
  const Vec3Column& previousPosition() const { return previous_; }
  const Vec3Column& acceleration() const { return acceleration_; }
  const FloatColumn& age() const { return age_; }
  const FloatColumn& lifetime() const { return lifetime_; }
  const FloatColumn& mass() const { return mass_; }
  const FloatColumn& inverseMass() const { return inverseMass_; }
  const std::vector<std::uint64_t>& id() const { return id_; }
  const std::vector<std::int64_t>& birthTick() const { return birthTick_; }
  const std::vector<std::uint8_t>& dead() const { return dead_; }

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

  /// Rows the columns currently hold (>= size()); grows geometrically, never past maxParticles.
  std::size_t storageRows() const { return storageRows_; }
  /// Bytes a row takes over every column, the named attributes included: the pool's columns hold
  /// storageRows() · bytesPerRow() bytes.
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
                                                   std::span<const std::int64_t> births,
                                                   std::uint64_t nextId, std::int64_t tick);

 private:
  struct NamedColumn {
    std::string name;
    float initial = 0.0f;
    FloatColumn values;
  };

  void grow(std::size_t rows);
  std::size_t firstDeadRow() const;  // size() when nobody is flagged

  std::size_t maxParticles_;
  std::size_t size_ = 0;
  std::size_t storageRows_ = 0;
  std::size_t firstUnstepped_ = 0;
  std::uint64_t nextId_ = 0;
  std::uint64_t droppedSpawns_ = 0;
  std::uint64_t rowsVersion_ = 0;
  bool keepsAcceleration_ = false;

  Vec3Column position_, velocity_, previous_, acceleration_;
  FloatColumn age_, lifetime_, mass_, inverseMass_;
  std::vector<std::uint64_t> id_;
  std::vector<std::int64_t> birthTick_;
  std::vector<std::uint8_t> dead_;
  std::vector<NamedColumn> attributes_;
};

}  // namespace tickfx
