// Emitters: where, when and how particles are born.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <variant>
#include <vector>

#include "particles/EmissionRate.h"
#include "particles/LifeAttribute.h"
#include "particles/ParticleEvent.h"
#include "particles/ParticlePool.h"
#include "particles/Random.h"
#include "particles/SettingProblem.h"
#include "particles/Shard.h"

namespace tickfx {

/// All particles start at the emitter's position.
struct PointShape {};
/// Uniform in a ball of `radius` metres, or on its surface.
struct SphereShape {
  double radius = 1.0;
  bool surface = false;
};
/// Uniform in an axis-aligned box of edge lengths `size` metres, centred on the emitter.
struct BoxShape {
  Eigen::Vector3d size = Eigen::Vector3d::Ones();
};
/// Uniform on a disc of `radius` metres facing `normal`.
struct DiscShape {
  double radius = 1.0;
  Eigen::Vector3d normal = Eigen::Vector3d::UnitY();
};
/// A fixed list of points, such as a cache read from a file (the core never reads files: io/ does
/// and hands the points over). The particle of serial s is born at point s mod N, offset by the
/// emitter's position; with `velocities` (one per point) it starts with that point's velocity,
/// without (empty) with the emitter's speed, direction and spread as any other shape. Points are
/// metres and m/s, taken as they are: with the emitter at the origin a particle is born at the
/// point's exact float bits (−0.0 included).
struct PointListShape {
  std::vector<Eigen::Vector3f> positions;   // metres, relative to the emitter's position; N >= 1
  std::vector<Eigen::Vector3f> velocities;  // m/s, one per point, or empty
};
using EmitterShape = std::variant<PointShape, SphereShape, BoxShape, DiscShape, PointListShape>;

struct SpawnRecipe;  // particles/SpawnBatch.h (internal)

/// `count` particles at once at the first tick starting at or after `time` seconds.
struct Burst {
  double time = 0.0;
  std::uint64_t count = 0;
};

/// The most sub-emitters in a chain of parents (a child's parent's parent ...): 8.
inline constexpr int kMaxSubEmitterDepth = 8;

/// What makes an emitter a sub-emitter: it emits from another emitter's particles at their
/// events instead of at times (it has no rate and no bursts). Its children start at the event's
/// position plus the emitter's position and shape offset, with the emitter's speed, spread,
/// lifetime and mass, their random numbers a pure function of (seed, this emitter, parent id,
/// event ordinal, child index).
struct SubEmitterSettings {
  std::string parent;  // the parent emitter's name; empty: not a sub-emitter
  EmitterEvent on = EmitterEvent::None;
  /// Children per event: countMin when equal to countMax, else drawn per event in [min, max].
  std::uint64_t countMin = 1, countMax = 1;
  double inheritVelocity = 0.0;  // fraction (0 to 1) of the parent's velocity at the event
  bool alongNormal = false;      // direction: the contact's normal (on = collision only)
  /// Attributes the children copy from the parent at the event ("Cd", "pscale", a custom or hit
  /// attribute): its value then, kept in a pool column for the children's life.
  std::vector<std::string> inherit;
  bool firstOnly = false;  // only the parent's first event of the kind
};

/// An emitter's settings. Scalars are double so that the per-particle arithmetic, done in double
/// and rounded to float once, never round-trips a float through double.
struct EmitterSettings {
  std::string name;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // metres
  EmitterShape shape = PointShape{};
  /// Particles per second while active; resolved to 10⁻⁶ particle/s and counted exactly.
  double rate = 0.0;
  double start = 0.0;                                     // seconds: rate emission begins
  double stop = std::numeric_limits<double>::infinity();  // seconds: rate emission ends
  std::vector<Burst> bursts;
  Eigen::Vector3d direction = Eigen::Vector3d::UnitY();       // initial direction (normalised)
  double speed = 0.0;                                         // m/s
  double speedJitter = 0.0;                                   // fraction: speed · (1 ± jitter)
  double spreadDegrees = 0.0;                                 // half-angle of the cone, in [0, 180]
  double lifetime = std::numeric_limits<double>::infinity();  // seconds
  double lifetimeJitter = 0.0;                                // fraction: lifetime · (1 ± jitter)
  double mass = 1.0;                                          // kilograms
  SubEmitterSettings sub;                                     // parent and event, for a sub-emitter
  /// Attributes over life of this emitter's particles (each name once; not one it inherits).
  std::vector<LifeAttributeSettings> attributes;

  /// What an Emitter refuses in these settings (empty: it accepts them), each problem keyed as
  /// effect files write it: "rate", "stop", "direction", "normal", "bursts.<i>.time", and "file"
  /// for a point list. Numbers must be finite and in range, and `direction` (and a disc's
  /// `normal`) long enough to normalise in double precision (see normalisable()).
  SettingProblems validate() const;
};

/// Spawns particles for one emitter. Emission is a pure function of the tick: rate emission as
/// EmissionRate says (a whole emission makes ⌊rate·(stop − start)⌋ particles whatever the step
/// rate), each burst at the first tick at or after its time (exact::tickAtOrAfter). So the
/// count is the same for any frame times, and each particle's serial (the input of its random
/// numbers) is known without replaying earlier ticks.
class Emitter {
 public:
  /// `index` is the emitter's place in the effect (part of its random keys); throws
  /// std::invalid_argument with the first of settings.validate(), or for a step rate <= 0.
  Emitter(EmitterSettings settings, std::uint32_t index, std::int64_t stepRateHz);

  /// Particles this emitter starts before tick `tick` (its serial counter at that tick).
  std::uint64_t serialBefore(std::int64_t tick) const;

  /// Spawns the particles of tick `tick` into `pool`; returns how many were attempted (spawns the
  /// pool refused are counted there). A shard's pool gets its own particles of the tick
  /// (Shard::ownerOfSerial) with the ids the whole run gives them; the ids of the others are
  /// counted as handed out. The caller keeps a shard's pool from reaching maxParticles: a cap is
  /// a count over every shard.
  std::uint64_t emit(ParticlePool& pool, std::uint64_t seed, std::int64_t tick,
                     const Shard& shard = {}) const;

  /// The particle with serial `serial` as it is born (pure function of seed, index and serial),
  /// worked out on its own, one draw after another: the reference that sampleBatch() and emit()
  /// match bit for bit.
  ParticleInit sample(std::uint64_t seed, std::uint64_t serial) const;

  /// out[k] = sample(seed, firstSerial + k · stride) for every k (stride >= 1), bit for bit, drawn
  /// a batch at a time: each step for many particles before the next, in vectorised loops. How
  /// emit() fills a pool's rows; any out.size() gives the same values.
  void sampleBatch(std::uint64_t seed, std::uint64_t firstSerial, std::uint64_t stride,
                   std::span<ParticleInit> out) const;

  /// A sub-emitter's children for `event`: how many (count, or drawn per event from count_range;
  /// 0 past the first event when first_only), and child `child` as it is born. Pure functions of
  /// (seed, this emitter, parent id, event ordinal, child index).
  std::uint64_t childCount(std::uint64_t seed, const ParticleEvent& event) const;
  ParticleInit sampleChild(std::uint64_t seed, const ParticleEvent& event,
                           std::uint64_t child) const;
  bool isSubEmitter() const { return !s_.sub.parent.empty(); }
  std::uint32_t index() const { return index_; }

  const EmitterSettings& settings() const { return s_; }

 private:
  std::uint64_t rateCountBefore(std::int64_t tick) const;
  // What sampleBatch() needs of this emitter for `seed`.
  SpawnRecipe spawnRecipe(std::uint64_t seed) const;
  // A particle of `random` at `origin` plus the shape's offset, going along `dir` (unit) within the
  // spread around it (b1, b2 completing it to a basis).
  ParticleInit draw(const ParticleRandom& random, const Eigen::Vector3d& dir,
                    const Eigen::Vector3d& b1, const Eigen::Vector3d& b2,
                    Eigen::Vector3d& offset) const;

  EmitterSettings s_;
  std::uint32_t index_;
  std::int64_t stepRate_;
  EmissionRate rate_{0, 0.0, 0.0, 1};
  std::vector<std::pair<std::int64_t, std::uint64_t>> burstTicks_;  // (tick, count), sorted
  // What sample() would otherwise work out for every particle, worked out once (the same bits):
  // the bases around the direction and the disc's normal, the cosine of the spread.
  Eigen::Vector3d directionB1_, directionB2_, discB1_, discB2_;
  double cosSpread_ = 1.0;
};

}  // namespace tickfx
