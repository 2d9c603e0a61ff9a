// An emitter's particles drawn a batch at a time: Emitter::sample()'s values, bit for bit, with
// each step done for the whole batch before the next (every draw of one purpose, then every sine
// and cosine, ...), in loops the compiler vectorises. Internal: Emitter::emit() and
// Emitter::sampleBatch() use it; not installed.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>

#include "particles/ParticlePool.h"

namespace tickfx {

/// What Emitter::sample() makes of an emitter's settings, for one seed, worked out once for all
/// the particles of an emission. Vectors and scalars are those sample() uses (the direction
/// normalised, its bases, the cosine of the spread), so that every value comes out the same.
struct SpawnRecipe {
  enum class Shape { Point, Sphere, Box, Disc, PointList };
  Shape shape = Shape::Point;
  std::uint64_t emitterKey = 0;  // emitterKey(seed, the emitter's index)
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d boxSize = Eigen::Vector3d::Ones();
  double radius = 1.0;  // sphere, disc
  bool surface = false;
  Eigen::Vector3d discB1 = Eigen::Vector3d::UnitX(), discB2 = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d direction = Eigen::Vector3d::UnitY();
  Eigen::Vector3d directionB1 = Eigen::Vector3d::UnitX(), directionB2 = Eigen::Vector3d::UnitZ();
  double spreadDegrees = 0.0;
  double cosSpread = 1.0;
  double speed = 0.0, speedJitter = 0.0;
  double lifetime = 0.0, lifetimeJitter = 0.0;
  double mass = 1.0;
  // A point list's points and velocities (borrowed: they outlive the recipe).
  std::span<const Eigen::Vector3f> points, pointVelocities;
};

/// out[k] = the particle of serial firstSerial + k · stride (stride >= 1), for every k: the bits
/// of Emitter::sample() for that serial, whatever out.size() and however a burst is cut into
/// batches.
void spawnBatch(const SpawnRecipe& recipe, std::uint64_t firstSerial, std::uint64_t stride,
                std::span<ParticleInit> out);

/// spawnBatch() written column by column: row k of each of `out`'s columns gets the position,
/// velocity, lifetime and mass of the particle of serial firstSerial + k · stride, for k < count.
/// The same bits; the columns are written in runs (no per-row gather), as emit() fills a pool.
/// Runs on activeIsa() (particles/Isa.h): the same bits on every path.
void spawnRows(const SpawnRecipe& recipe, std::uint64_t firstSerial, std::uint64_t stride,
               std::size_t count, const SpawnTargets& out);

}  // namespace tickfx
