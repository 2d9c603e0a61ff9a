// Emitters: where, when and how particles are born.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <string>
#include <variant>
#include <vector>

#include "particles/EmissionRate.h"
#include "particles/ParticlePool.h"
#include "particles/SettingProblem.h"

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

/// `count` particles at once at the first tick starting at or after `time` seconds.
struct Burst {
  double time = 0.0;
  std::uint64_t count = 0;
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
  /// pool refused are counted there).
  std::uint64_t emit(ParticlePool& pool, std::uint64_t seed, std::int64_t tick) const;

  /// The particle with serial `serial` as it is born (pure function of seed, index and serial).
  ParticleInit sample(std::uint64_t seed, std::uint64_t serial) const;

  const EmitterSettings& settings() const { return s_; }

 private:
  std::uint64_t rateCountBefore(std::int64_t tick) const;

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
