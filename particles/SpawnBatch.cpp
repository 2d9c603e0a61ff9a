#include "particles/SpawnBatch.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>

#include "particles/Assert.h"
#include "particles/DetMath.h"
#include "particles/DetMathBlock.h"
#include "particles/DetMathKernels.h"
#include "particles/Isa.h"
#include "particles/Random.h"

#ifdef TICKFX_AVX2_CLONES
#include <immintrin.h>
#endif

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

// The identity, for draws stored as they are.
struct AsDrawn {
  double operator()(std::size_t, double u) const { return u; }
};

// out[k][i] = map(k, ParticleRandom::uniform(purposes[k]) of particle i), for every particle of
// the chunk: what a draw becomes is worked out in the loop that draws it. The draws are 64-bit
// integer multiplies: scalar in the SSE2 build (emulated they are no faster there), four lanes
// wide in the AVX2 path. A few purposes a loop share the key's load.
template <std::size_t K, class Map = AsDrawn>
void drawUniforms(const Chunk& c, const std::array<RandomPurpose, K>& purposes,
                  const std::array<double*, K>& out, Map map = {}) {
  std::array<std::uint32_t, K> p;
  for (std::size_t k = 0; k < K; ++k) p[k] = static_cast<std::uint32_t>(purposes[k]);
  for (std::size_t i = 0; i < c.n; ++i) {
    const std::uint64_t key = c.key[i];
    for (std::size_t k = 0; k < K; ++k) out[k][i] = map(k, uniformFromBits(purposeBits(key, p[k])));
  }
}

template <class Map = AsDrawn>
void drawUniform(const Chunk& c, RandomPurpose purpose, double* out, Map map = {}) {
  drawUniforms<1>(c, {purpose}, {out}, map);
}

// A uniform number of turns in [0, 1) as an angle: below 2π, far inside the range of the
// vectorised reduction (det::kernel::sincosSmall, |x| < 2^19), so none needs
// det::sincosBlock()'s fallback.
double angleOfTurns(double turns) {
  static_assert(kTwoPi < det::kernel::kCodyWaiteLimit);
  return kTwoPi * turns;
}

// c.sine and c.cosine of the angles. Inline, so that the AVX2 path vectorises it with its width.
void sincosOf(const double* angles, Chunk& c) {
  det::kernel::sincosSmall(angles, c.sine, c.cosine, c.n);
}

#ifdef TICKFX_AVX2_CLONES
// det::sqrtClampedBlock() four lanes wide: the same max (0 for nan and −0) and IEEE square root.
[[gnu::target("avx2")]] void sqrtClampedAvx2(double* x, std::size_t n) {
  std::size_t i = 0;
  const __m256d zero = _mm256_setzero_pd();
  for (; i + 4 <= n; i += 4)
    _mm256_storeu_pd(x + i, _mm256_sqrt_pd(_mm256_max_pd(_mm256_loadu_pd(x + i), zero)));
  for (; i < n; ++i) x[i] = std::sqrt(std::max(0.0, x[i]));
}
#endif

// x[i] = sqrt(max(0, x[i])), on the path's vector width.
template <bool kAvx2>
void sqrtClamped(double* x, std::size_t n) {
#ifdef TICKFX_AVX2_CLONES
  if constexpr (kAvx2) {
    sqrtClampedAvx2(x, n);
    return;
  }
#endif
  det::sqrtClampedBlock(x, n);
}

void boxOffsets(const SpawnRecipe& r, Chunk& c) {
  drawUniforms<3>(c, {RandomPurpose::PositionU, RandomPurpose::PositionV, RandomPurpose::PositionW},
                  {c.offset[0], c.offset[1], c.offset[2]},
                  [&](std::size_t axis, double u) { return (u - 0.5) * r.boxSize[axis]; });
}

template <bool kAvx2>
void sphereOffsets(const SpawnRecipe& r, Chunk& c) {
  // c.u becomes z, c.v the angle about the z axis, then the distance from it on the unit sphere.
  drawUniforms<2>(c, {RandomPurpose::PositionU, RandomPurpose::PositionV}, {c.u, c.v},
                  [](std::size_t k, double u) { return k == 0 ? 1.0 - 2.0 * u : angleOfTurns(u); });
  sincosOf(c.v, c);
  for (std::size_t i = 0; i < c.n; ++i) c.v[i] = 1.0 - c.u[i] * c.u[i];
  sqrtClamped<kAvx2>(c.v, c.n);
  // c.w becomes the radius: the sphere's, or the cube root's share of it inside.
  if (r.surface) {
    std::fill_n(c.w, c.n, r.radius);
  } else {
    double uniform[kChunk];
    drawUniform(c, RandomPurpose::PositionW, uniform);
    det::kernel::cbrtBlock(uniform, c.w, c.n);  // inline: the AVX2 path vectorises it
    for (std::size_t i = 0; i < c.n; ++i) c.w[i] = r.radius * c.w[i];
  }
  for (std::size_t i = 0; i < c.n; ++i) {
    c.offset[0][i] = c.w[i] * (c.v[i] * c.cosine[i]);
    c.offset[1][i] = c.w[i] * (c.v[i] * c.sine[i]);
    c.offset[2][i] = c.w[i] * c.u[i];
  }
}

template <bool kAvx2>
void discOffsets(const SpawnRecipe& r, Chunk& c) {
  drawUniforms<2>(c, {RandomPurpose::PositionU, RandomPurpose::PositionV}, {c.u, c.v},
                  [](std::size_t k, double u) { return k == 0 ? u : angleOfTurns(u); });
  sqrtClamped<kAvx2>(c.u, c.n);  // a uniform number is >= 0: the clamp changes nothing
  sincosOf(c.v, c);
  for (std::size_t i = 0; i < c.n; ++i) {
    const double radius = r.radius * c.u[i];
    const double along1 = radius * c.cosine[i], along2 = radius * c.sine[i];
    for (int axis = 0; axis < 3; ++axis)
      c.offset[axis][i] = along1 * r.discB1[axis] + along2 * r.discB2[axis];
  }
}

template <bool kAvx2>
void shapeOffsets(const SpawnRecipe& r, Chunk& c) {
  switch (r.shape) {
    case SpawnRecipe::Shape::Sphere:
      sphereOffsets<kAvx2>(r, c);
      return;
    case SpawnRecipe::Shape::Box:
      boxOffsets(r, c);
      return;
    case SpawnRecipe::Shape::Disc:
      discOffsets<kAvx2>(r, c);
      return;
    case SpawnRecipe::Shape::Point:
    case SpawnRecipe::Shape::PointList:
      for (auto& axis : c.offset) std::fill_n(axis, c.n, 0.0);
      return;
  }
}

// Uniform over the spherical cap of half-angle `spread` around the direction.
template <bool kAvx2>
void spreadDirections(const SpawnRecipe& r, Chunk& c) {
  // c.u becomes cos θ; c.v the angle about the direction, then sin θ.
  const double capHeight = 1.0 - r.cosSpread;
  drawUniforms<2>(
      c, {RandomPurpose::DirectionU, RandomPurpose::DirectionV}, {c.u, c.v},
      [&](std::size_t k, double u) { return k == 0 ? 1.0 - u * capHeight : angleOfTurns(u); });
  sincosOf(c.v, c);
  for (std::size_t i = 0; i < c.n; ++i) c.v[i] = 1.0 - c.u[i] * c.u[i];
  sqrtClamped<kAvx2>(c.v, c.n);
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
void jittered(const Chunk& c, RandomPurpose purpose, double value, double jitter, double* out) {
  if (jitter == 0.0) {
    std::fill_n(out, c.n, value);
    return;
  }
  drawUniform(c, purpose, out,
              [&](std::size_t, double u) { return value * (1.0 + jitter * (2.0 * u - 1.0)); });
}

// The emitter's position plus the offset, rounded to float once; for a point list, its point.
void writePositions(const SpawnRecipe& r, const Chunk& c, std::uint64_t first, std::uint64_t stride,
                    const SpawnTargets& out) {
  if (r.shape != SpawnRecipe::Shape::PointList) {
    for (int axis = 0; axis < 3; ++axis) {
      const double origin = r.position[axis];
      float* __restrict to = out.position[axis];
      for (std::size_t i = 0; i < c.n; ++i) to[i] = static_cast<float>(origin + c.offset[axis][i]);
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
    const Eigen::Vector3f at = atOrigin ? p : Eigen::Vector3f(origin + p);
    for (int axis = 0; axis < 3; ++axis) out.position[axis][i] = at[axis];
    if (!r.pointVelocities.empty()) {
      const Eigen::Vector3f& v = r.pointVelocities[static_cast<std::size_t>(point)];
      for (int axis = 0; axis < 3; ++axis) out.velocity[axis][i] = v[axis];
    }
    point += step;
    if (point >= count) point -= count;
  }
}

template <bool kAvx2>
void spawnChunk(const SpawnRecipe& r, std::uint64_t first, std::uint64_t stride, Chunk& c,
                const SpawnTargets& out) {
  drawKeys(r.emitterKey, first, stride, c);
  shapeOffsets<kAvx2>(r, c);
  // A point list with velocities gives them in writePositions(): no direction or speed drawn.
  const bool listVelocities = !r.pointVelocities.empty();
  if (!listVelocities) {
    if (r.spreadDegrees > 0.0) spreadDirections<kAvx2>(r, c);
    jittered(c, RandomPurpose::Speed, r.speed, r.speedJitter, c.speed);
  }
  jittered(c, RandomPurpose::Lifetime, r.lifetime, r.lifetimeJitter, c.life);
  const auto mass = static_cast<float>(r.mass);
  float* __restrict life = out.lifetime;
  float* __restrict masses = out.mass;
  for (std::size_t i = 0; i < c.n; ++i) {
    life[i] = static_cast<float>(c.life[i]);
    masses[i] = mass;
  }
  if (!listVelocities) {
    const bool spread = r.spreadDegrees > 0.0;
    for (int axis = 0; axis < 3; ++axis) {
      float* __restrict to = out.velocity[axis];
      if (spread) {
        for (std::size_t i = 0; i < c.n; ++i)
          to[i] = static_cast<float>(c.speed[i] * c.dir[axis][i]);
      } else {
        const double d = r.direction[axis];
        for (std::size_t i = 0; i < c.n; ++i) to[i] = static_cast<float>(c.speed[i] * d);
      }
    }
  }
  writePositions(r, c, first, stride, out);
}

#ifdef TICKFX_AVX2_CLONES
// spawnChunk() compiled for AVX2: everything it calls in this file (and the sine and cosine
// kernels) is inlined here and vectorised four doubles wide, where the baseline build has two.
// The same operations in the same order: integer ones, and IEEE ones that AVX2 rounds as SSE2
// does (no FMA here, and -ffp-contract=off), so the same bits.
[[gnu::target("avx2"), gnu::flatten]] void spawnChunkAvx2(const SpawnRecipe& r, std::uint64_t first,
                                                          std::uint64_t stride, Chunk& c,
                                                          const SpawnTargets& out) {
  spawnChunk<true>(r, first, stride, c, out);
}

// spawnChunk() compiled for AVX-512 (F, DQ, VL), flattened as the AVX2 clone is: its loops
// vectorise eight doubles wide, and the draws' 64-bit multiplies become one instruction
// (vpmullq, AVX-512DQ), which SSE2 and AVX2 emulate with three. The same integer and IEEE
// operations, so the same bits (test_emitter_batch forces every path).
[[gnu::target("avx2,avx512f,avx512dq,avx512vl"), gnu::flatten]] void spawnChunkAvx512(
    const SpawnRecipe& r, std::uint64_t first, std::uint64_t stride, Chunk& c,
    const SpawnTargets& out) {
  spawnChunk<true>(r, first, stride, c, out);
}
#endif

SpawnTargets advanced(const SpawnTargets& t, std::size_t rows) {
  SpawnTargets out = t;
  for (int axis = 0; axis < 3; ++axis) {
    out.position[axis] += rows;
    out.velocity[axis] += rows;
  }
  out.lifetime += rows;
  out.mass += rows;
  return out;
}

}  // namespace

void spawnRows(const SpawnRecipe& recipe, std::uint64_t firstSerial, std::uint64_t stride,
               std::size_t count, const SpawnTargets& out) {
  // The path is chosen once: every chunk of the batch takes it.
  auto* chunkOn = &spawnChunk<false>;
#ifdef TICKFX_AVX2_CLONES
  switch (activeIsa()) {
    case Isa::Avx512:
      chunkOn = &spawnChunkAvx512;
      break;
    case Isa::Avx2:
      chunkOn = &spawnChunkAvx2;
      break;
    case Isa::Baseline:
      break;
  }
#endif
  Chunk chunk;
  for (std::size_t k = 0; k < count; k += kChunk) {
    chunk.n = std::min(kChunk, count - k);
    chunkOn(recipe, firstSerial + k * stride, stride, chunk, advanced(out, k));
  }
}

void spawnBatch(const SpawnRecipe& recipe, std::uint64_t firstSerial, std::uint64_t stride,
                std::span<ParticleInit> out) {
  // Through columns of one chunk, then gathered into the rows: the values spawnRows() writes.
  float columns[8][kChunk];
  const SpawnTargets targets{{columns[0], columns[1], columns[2]},
                             {columns[3], columns[4], columns[5]},
                             columns[6],
                             columns[7]};
  for (std::size_t k = 0; k < out.size(); k += kChunk) {
    const std::size_t n = std::min(kChunk, out.size() - k);
    spawnRows(recipe, firstSerial + k * stride, stride, n, targets);
    for (std::size_t i = 0; i < n; ++i) {
      ParticleInit& p = out[k + i];
      for (int axis = 0; axis < 3; ++axis) {
        p.position[axis] = columns[axis][i];
        p.velocity[axis] = columns[3 + axis][i];
      }
      p.lifetime = columns[6][i];
      p.mass = columns[7][i];
    }
  }
}

}  // namespace tickfx
