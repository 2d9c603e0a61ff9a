#include "particles/SpawnBatch.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "particles/DetMath.h"
#include "particles/DetMathBlock.h"
#include "particles/Random.h"

namespace tickfx {
namespace {

// Particles a pass works on: their columns (below, 14 KiB) stay in the L1 cache between passes.
constexpr std::size_t kChunk = 128;
constexpr double kTwoPi = 2.0 * det::kPi;

// One chunk's particles, column by column, in double until they are rounded to float once.
struct Chunk {
  std::size_t n = 0;
  std::uint64_t key[kChunk];  // particleKey() of each
  double offset[3][kChunk];   // the shape's offset from the emitter's position
  double dir[3][kChunk];      // unit direction, with the spread
  double speed[kChunk], life[kChunk];
  double u[kChunk], v[kChunk], w[kChunk], sine[kChunk], cosine[kChunk];  // scratch
};

void drawKeys(std::uint64_t emitterKey, std::uint64_t first, std::uint64_t stride, Chunk& c) {
  for (std::size_t i = 0; i < c.n; ++i) c.key[i] = particleKey(emitterKey, first + i * stride);
}

// out[k][i] = ParticleRandom::uniform(purposes[k]) of particle i, for every particle of the chunk.
// The draws are 64-bit integer multiplies, which SSE2 lacks (emulated they are no faster): a
// scalar loop, a few purposes in each to share the key's load and the loop's overhead.
template <std::size_t K>
void drawUniforms(const Chunk& c, const std::array<RandomPurpose, K>& purposes,
                  const std::array<double*, K>& out) {
  std::array<std::uint32_t, K> p;
  for (std::size_t k = 0; k < K; ++k) p[k] = static_cast<std::uint32_t>(purposes[k]);
  for (std::size_t i = 0; i < c.n; ++i) {
    const std::uint64_t key = c.key[i];
    for (std::size_t k = 0; k < K; ++k) out[k][i] = uniformFromBits(purposeBits(key, p[k]));
  }
}

void drawUniform(const Chunk& c, RandomPurpose purpose, double* out) {
  drawUniforms<1>(c, {purpose}, {out});
}

void sincosOfTurns(const double* turns, Chunk& c) {
  for (std::size_t i = 0; i < c.n; ++i) c.w[i] = kTwoPi * turns[i];
  det::sincosBlock(c.w, c.sine, c.cosine, c.n);
}

void boxOffsets(const SpawnRecipe& r, Chunk& c) {
  drawUniforms<3>(c, {RandomPurpose::PositionU, RandomPurpose::PositionV, RandomPurpose::PositionW},
                  {c.offset[0], c.offset[1], c.offset[2]});
  for (int axis = 0; axis < 3; ++axis) {
    const double size = r.boxSize[axis];
    for (std::size_t i = 0; i < c.n; ++i) c.offset[axis][i] = (c.offset[axis][i] - 0.5) * size;
  }
}

void sphereOffsets(const SpawnRecipe& r, Chunk& c) {
  drawUniforms<2>(c, {RandomPurpose::PositionU, RandomPurpose::PositionV}, {c.u, c.v});
  sincosOfTurns(c.v, c);
  // c.u becomes z, c.v the distance from the z axis on the unit sphere.
  for (std::size_t i = 0; i < c.n; ++i) {
    c.u[i] = 1.0 - 2.0 * c.u[i];
    c.v[i] = 1.0 - c.u[i] * c.u[i];
  }
  det::sqrtClampedBlock(c.v, c.n);
  // c.w becomes the radius: the sphere's, or the cube root's share of it inside.
  if (r.surface) {
    std::fill_n(c.w, c.n, r.radius);
  } else {
    double uniform[kChunk];
    drawUniform(c, RandomPurpose::PositionW, uniform);
    det::cbrtBlock(uniform, c.w, c.n);
    for (std::size_t i = 0; i < c.n; ++i) c.w[i] = r.radius * c.w[i];
  }
  for (std::size_t i = 0; i < c.n; ++i) {
    c.offset[0][i] = c.w[i] * (c.v[i] * c.cosine[i]);
    c.offset[1][i] = c.w[i] * (c.v[i] * c.sine[i]);
    c.offset[2][i] = c.w[i] * c.u[i];
  }
}

void discOffsets(const SpawnRecipe& r, Chunk& c) {
  drawUniforms<2>(c, {RandomPurpose::PositionU, RandomPurpose::PositionV}, {c.u, c.v});
  det::sqrtClampedBlock(c.u, c.n);  // a uniform number is >= 0: the clamp changes nothing
  sincosOfTurns(c.v, c);
  for (std::size_t i = 0; i < c.n; ++i) {
    const double radius = r.radius * c.u[i];
    const double along1 = radius * c.cosine[i], along2 = radius * c.sine[i];
    for (int axis = 0; axis < 3; ++axis)
      c.offset[axis][i] = along1 * r.discB1[axis] + along2 * r.discB2[axis];
  }
}

void shapeOffsets(const SpawnRecipe& r, Chunk& c) {
  switch (r.shape) {
    case SpawnRecipe::Shape::Sphere:
      sphereOffsets(r, c);
      return;
    case SpawnRecipe::Shape::Box:
      boxOffsets(r, c);
      return;
    case SpawnRecipe::Shape::Disc:
      discOffsets(r, c);
      return;
    case SpawnRecipe::Shape::Point:
    case SpawnRecipe::Shape::PointList:
      for (auto& axis : c.offset) std::fill_n(axis, c.n, 0.0);
      return;
  }
}

// Uniform over the spherical cap of half-angle `spread` around the direction.
void spreadDirections(const SpawnRecipe& r, Chunk& c) {
  drawUniforms<2>(c, {RandomPurpose::DirectionU, RandomPurpose::DirectionV}, {c.u, c.v});
  sincosOfTurns(c.v, c);
  // c.u becomes cos θ, c.v sin θ.
  for (std::size_t i = 0; i < c.n; ++i) {
    c.u[i] = 1.0 - c.u[i] * (1.0 - r.cosSpread);
    c.v[i] = 1.0 - c.u[i] * c.u[i];
  }
  det::sqrtClampedBlock(c.v, c.n);
  for (std::size_t i = 0; i < c.n; ++i) {
    const double along1 = c.v[i] * c.cosine[i], along2 = c.v[i] * c.sine[i];
    for (int axis = 0; axis < 3; ++axis) {
      c.dir[axis][i] =
          along1 * r.directionB1[axis] + along2 * r.directionB2[axis] + c.u[i] * r.direction[axis];
    }
  }
}

// value · (1 ± jitter), the sign and size drawn for `purpose`. Without jitter the factor is
// exactly 1 (1 + 0 · (2u − 1) = 1 for any u), so nothing is drawn.
void jittered(const Chunk& c, RandomPurpose purpose, double value, double jitter, double* out,
              double* scratch) {
  if (jitter == 0.0) {
    std::fill_n(out, c.n, value);
    return;
  }
  drawUniform(c, purpose, scratch);
  for (std::size_t i = 0; i < c.n; ++i) out[i] = value * (1.0 + jitter * (2.0 * scratch[i] - 1.0));
}

// The emitter's position plus the offset, rounded to float once; for a point list, its point.
void writePositions(const SpawnRecipe& r, const Chunk& c, std::uint64_t first, std::uint64_t stride,
                    ParticleInit* out) {
  if (r.shape != SpawnRecipe::Shape::PointList) {
    for (std::size_t i = 0; i < c.n; ++i) {
      for (int axis = 0; axis < 3; ++axis)
        out[i].position[axis] = static_cast<float>(r.position[axis] + c.offset[axis][i]);
    }
    return;
  }
  // Point s mod N, stepped along the serials without a division per particle, unless the serials
  // wrap past 2^64 within the chunk (s mod N jumps there). In float, as Emitter::sample() adds
  // them; at the origin the point's bits as they are.
  const std::uint64_t count = r.points.size();
  const std::uint64_t span = static_cast<std::uint64_t>(c.n - 1);
  const bool wraps = span > 0 && stride > (~std::uint64_t{0} - first) / span;
  const std::uint64_t step = stride % count;
  std::uint64_t point = first % count;
  const bool atOrigin = r.position.isZero(0.0);
  const Eigen::Vector3f origin = r.position.cast<float>();
  for (std::size_t i = 0; i < c.n; ++i) {
    if (wraps) point = (first + i * stride) % count;
    const Eigen::Vector3f& p = r.points[static_cast<std::size_t>(point)];
    out[i].position = atOrigin ? p : Eigen::Vector3f(origin + p);
    if (!r.pointVelocities.empty())
      out[i].velocity = r.pointVelocities[static_cast<std::size_t>(point)];
    point += step;
    if (point >= count) point -= count;
  }
}

void spawnChunk(const SpawnRecipe& r, std::uint64_t first, std::uint64_t stride, Chunk& c,
                ParticleInit* out) {
  drawKeys(r.emitterKey, first, stride, c);
  shapeOffsets(r, c);
  // A point list with velocities gives them in writePositions(): no direction or speed drawn.
  const bool listVelocities = !r.pointVelocities.empty();
  if (!listVelocities) {
    if (r.spreadDegrees > 0.0) spreadDirections(r, c);
    jittered(c, RandomPurpose::Speed, r.speed, r.speedJitter, c.speed, c.u);
  }
  jittered(c, RandomPurpose::Lifetime, r.lifetime, r.lifetimeJitter, c.life, c.u);
  const auto mass = static_cast<float>(r.mass);
  for (std::size_t i = 0; i < c.n; ++i) {
    out[i].lifetime = static_cast<float>(c.life[i]);
    out[i].mass = mass;
  }
  if (!listVelocities) {
    const bool spread = r.spreadDegrees > 0.0;
    for (std::size_t i = 0; i < c.n; ++i) {
      for (int axis = 0; axis < 3; ++axis) {
        const double d = spread ? c.dir[axis][i] : r.direction[axis];
        out[i].velocity[axis] = static_cast<float>(c.speed[i] * d);
      }
    }
  }
  writePositions(r, c, first, stride, out);
}

}  // namespace

void spawnBatch(const SpawnRecipe& recipe, std::uint64_t firstSerial, std::uint64_t stride,
                std::span<ParticleInit> out) {
  Chunk chunk;
  for (std::size_t k = 0; k < out.size(); k += kChunk) {
    chunk.n = std::min(kChunk, out.size() - k);
    spawnChunk(recipe, firstSerial + k * stride, stride, chunk, out.data() + k);
  }
}

}  // namespace tickfx
