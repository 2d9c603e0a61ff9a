// One rendered frame of particles: what a cache file holds.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "io/util/UninitialisedVector.h"
#include "particles/ParticlePool.h"

namespace tickfx {
class ParticleSystem;
}  // namespace tickfx

namespace tickfx::io {

/// A copy of the particles as a frame shows them: the state at the frame's own time (see
/// ParticleSystem::renderPositions). Rows are in id order.
struct FrameData {
  std::int64_t frame = 0;    // frame number, from 1
  double timeSeconds = 0.0;  // the frame's time (for metadata only)
  /// resize() leaves new ids uninitialised, for the caller to write (no serial zero-fill).
  UninitialisedVector<std::uint64_t> id;
  Vec3Column position;  // metres
  Vec3Column velocity;  // metres per second
  FloatColumn age;      // seconds
  FloatColumn life;     // seconds (lifetime; +inf for immortal particles)
  FloatColumn mass;     // kilograms
  std::vector<std::string> attributeNames;
  std::vector<FloatColumn> attributes;

  std::size_t size() const { return id.size(); }
  /// Sizes every column for `rows` particles, with one attribute column per name (values, ids
  /// included, left uninitialised for the reader to fill).
  void resize(std::size_t rows, std::vector<std::string> names);
};

/// Captures `system` as frame `frame` at time `timeSeconds` (the time its last advance() reached):
/// positions, velocities and ages at that time; mass, lifetime and attributes of the newest tick.
FrameData captureFrame(const ParticleSystem& system, std::int64_t frame, double timeSeconds);

/// A 64-bit hash of what `data` shows: the row count, then the bits of every id, position,
/// velocity, age, lifetime, mass and attribute (names included), not the frame number or time.
/// Two caches of equal frames hold the same bits exactly when (barring collisions) this agrees.
std::uint64_t frameHash(const FrameData& data);

}  // namespace tickfx::io
