// Emitter::sampleBatch() and emit(): the particles drawn a batch at a time are sample()'s, the
// per-particle reference, bit for bit, for every shape with and without spread, any batch size,
// serial stride, shard and thread count.
#include <gtest/gtest.h>

#include <tbb/task_arena.h>
#include <Eigen/Core>
#include <algorithm>
#include <cstdint>
#include <limits>
#include <span>
#include <sstream>
#include <string>
#include <vector>

#include "CoreTestSupport.h"
#include "ForcedIsa.h"
#include "particles/Emitter.h"
#include "particles/ParallelFor.h"
#include "particles/ParticlePool.h"
#include "particles/Random.h"
#include "particles/Shard.h"
#include "particles/SpawnBatch.h"

namespace tickfx {
namespace {

using test::isasHere;

struct Case {
  std::string name;
  EmitterSettings settings;
};

EmitterSettings moving(EmitterShape shape, double spreadDegrees) {
  EmitterSettings s;
  s.position = Eigen::Vector3d(1.0, -2.0, 3.5);
  s.shape = std::move(shape);
  s.direction = Eigen::Vector3d(0.3, 1.0, -0.2);
  s.speed = 5.0;
  s.speedJitter = 0.3;
  s.spreadDegrees = spreadDegrees;
  s.lifetime = 2.0;
  s.lifetimeJitter = 0.5;
  s.mass = 0.7;
  return s;
}

// Every shape, each without spread, with a cone and with the whole sphere of directions; and the
// settings whose draws are skipped or special: no jitter, an infinite lifetime, an emitter at the
// origin (a point list keeps −0.0 there), point lists with and without velocities.
std::vector<Case> cases() {
  std::vector<Case> out;
  const std::vector<std::pair<std::string, EmitterShape>> shapes{
      {"point", PointShape{}},
      {"sphere", SphereShape{0.5, false}},
      {"sphere_surface", SphereShape{0.5, true}},
      {"box", BoxShape{Eigen::Vector3d(2.0, 1.0, 0.25)}},
      {"disc", DiscShape{0.8, Eigen::Vector3d(0.2, 1.0, -0.5)}},
      {"points",
       PointListShape{{{0.0f, 1.0f, 2.0f}, {-0.0f, 0.5f, -3.0f}, {4.0f, -0.0f, 0.25f}}, {}}},
      {"points_with_velocities", PointListShape{{{1.0f, 2.0f, 3.0f}, {-1.0f, 0.0f, 0.5f}},
                                                {{0.5f, -0.5f, 1.0f}, {-0.0f, 3.0f, 2.5f}}}}};
  for (const auto& [name, shape] : shapes) {
    for (const double spread : {0.0, 30.0, 180.0})
      out.push_back(
          {name + "_spread" + std::to_string(static_cast<int>(spread)), moving(shape, spread)});
  }
  EmitterSettings still = moving(BoxShape{Eigen::Vector3d(1.0, 2.0, 3.0)}, 10.0);
  still.speedJitter = 0.0;
  still.lifetimeJitter = 0.0;
  still.lifetime = std::numeric_limits<double>::infinity();
  out.push_back({"box_no_jitter_endless", still});
  EmitterSettings origin = moving(
      PointListShape{{{-0.0f, 1.0f, -0.0f}, {2.0f, -0.0f, 0.5f}, {0.0f, 0.0f, -0.0f}}, {}}, 45.0);
  origin.position = Eigen::Vector3d::Zero();
  out.push_back({"points_at_origin", origin});
  EmitterSettings pointAtOrigin = moving(PointShape{}, 0.0);
  pointAtOrigin.position = Eigen::Vector3d(-0.0, 0.0, -0.0);  // + 0.0 makes them +0.0
  out.push_back({"point_at_negative_zero", pointAtOrigin});
  return out;
}

std::string describe(const ParticleInit& p) {
  std::ostringstream s;
  s.precision(9);
  s << "position " << p.position.transpose() << ", velocity " << p.velocity.transpose()
    << ", lifetime " << p.lifetime << ", mass " << p.mass;
  return s.str();
}

#if defined(__x86_64__)
// The AVX2 and AVX-512 paths are chosen where the processor has them, and only there; the
// default is the widest.
TEST(EmitterBatch, TheWiderPathsAreAvailableExactlyWhereTheProcessorHasThem) {
  __builtin_cpu_init();
  const bool avx2 = __builtin_cpu_supports("avx2") != 0;
  const bool avx512 = avx2 && __builtin_cpu_supports("avx512f") != 0 &&
                      __builtin_cpu_supports("avx512dq") != 0 &&
                      __builtin_cpu_supports("avx512vl") != 0;
  EXPECT_EQ(isaAvailable(Isa::Avx2), avx2);
  EXPECT_EQ(isaAvailable(Isa::Avx512), avx512);
  EXPECT_TRUE(isaAvailable(Isa::Baseline));
  EXPECT_EQ(activeIsa(), avx512 ? Isa::Avx512 : avx2 ? Isa::Avx2 : Isa::Baseline);
  EXPECT_STREQ(isaName(Isa::Avx512), "AVX-512");
}
#endif

// Batch sizes around the sampler's chunk of 128 and emit()'s batch of 256, serials from 0, from
// far along and from just below 2^64 (the serials wrap there, and a point list's s mod N jumps),
// strides of a whole run and of shards.
TEST(EmitterBatch, SampleBatchGivesTheBitsOfSampleForEveryShapeSizeAndStride) {
  const std::uint64_t firsts[] = {0, 5, 123'456'789'012ULL, ~std::uint64_t{0} - 200};
  const std::uint64_t strides[] = {1, 2, 7, 65536};
  const std::size_t sizes[] = {1, 2, 127, 128, 129, 300};
  for (const Isa isa : isasHere()) {
    const ForcedIsa forced(isa);
    for (const Case& c : cases()) {
      for (const std::uint32_t index : {0u, 3u}) {
        const Emitter emitter(c.settings, index, 60);
        for (const std::uint64_t seed : {1ULL, 0xdeadbeefULL}) {
          for (const std::uint64_t first : firsts) {
            for (const std::uint64_t stride : strides) {
              for (const std::size_t n : sizes) {
                std::vector<ParticleInit> got(n);
                emitter.sampleBatch(seed, first, stride, got);
                for (std::size_t k = 0; k < n; ++k) {
                  const std::uint64_t serial = first + k * stride;
                  const ParticleInit want = emitter.sample(seed, serial);
                  ASSERT_TRUE(test::sameBits(got[k], want))
                      << isaName(isa) << ", " << c.name << ", emitter " << index << ", seed "
                      << seed << ", serial " << serial << " (batch of " << n << " from " << first
                      << " by " << stride << "): got " << describe(got[k]) << ", want "
                      << describe(want);
                }
              }
            }
          }
        }
      }
    }
  }
}

// The reference itself, pinned: a hash of sample()'s bits over every case, as the per-particle
// code made them before the batch sampler existed (and so as every golden hash was made). A
// change that moved both sample() and sampleBatch() together fails here.
TEST(EmitterBatch, TheReferenceKeepsItsBits) {
  std::uint64_t h = 0;
  for (const Case& c : cases()) {
    const Emitter emitter(c.settings, 1, 60);
    for (std::uint64_t serial = 0; serial < 200; ++serial) {
      const ParticleInit p = emitter.sample(9, serial * 1009);
      for (int k = 0; k < 3; ++k) {
        h = mix64(h ^ test::bitsOf(p.position[k]));
        h = mix64(h ^ test::bitsOf(p.velocity[k]));
      }
      h = mix64(h ^ test::bitsOf(p.lifetime));
      h = mix64(h ^ test::bitsOf(p.mass));
    }
  }
  EXPECT_EQ(h, 0x4c79851714373681ULL) << std::hex << h;
}

// One sampleBatch() call, or the same serials cut into batches of uneven sizes: the same bits,
// so a particle does not depend on where a block or a batch begins.
TEST(EmitterBatch, CuttingTheSerialsAnywhereChangesNoParticle) {
  for (const Case& c : cases()) {
    const Emitter emitter(c.settings, 2, 60);
    std::vector<ParticleInit> whole(1000);
    emitter.sampleBatch(77, 40, 3, whole);
    std::vector<ParticleInit> pieces(1000);
    std::size_t at = 0;
    for (std::size_t size = 1; at < pieces.size(); size = size * 3 % 257 + 1) {
      const std::size_t n = std::min(size, pieces.size() - at);
      emitter.sampleBatch(77, 40 + 3 * at, 3, std::span(pieces.data() + at, n));
      at += n;
    }
    for (std::size_t k = 0; k < whole.size(); ++k)
      ASSERT_TRUE(test::sameBits(whole[k], pieces[k])) << c.name << ", particle " << k;
    // Not all alike: the test compares particles that differ from one another.
    if (c.name.rfind("point_", 0) != 0 && c.name.find("spread0") == std::string::npos) {
      EXPECT_NE(whole[0].velocity, whole[1].velocity) << c.name;
    }
  }
}

ParticleInit rowOf(const ParticlePool& pool, std::size_t row) {
  const auto r = static_cast<Eigen::Index>(row);
  const auto at = [r](const Vec3Column& col) {
    return Eigen::Vector3f(col.x[r], col.y[r], col.z[r]);
  };
  return ParticleInit{at(pool.position()), at(pool.velocity()), pool.lifetime()[r], pool.mass()[r]};
}

// emit() on a shard (and on the whole run, shard 0 of 1), over ticks of a burst that spans
// several parallel blocks and a rate: every row holds sample() of its serial (an emitter alone
// from tick 0 gives the particle of serial s the id s), on 1 and 3 threads.
TEST(EmitterBatch, ShardedEmitFillsEachRowWithTheSampleOfItsSerial) {
  for (const Isa isa : isasHere()) {
    const ForcedIsa forced(isa);
    for (const Case& c : cases()) {
      EmitterSettings s = c.settings;
      s.bursts = {Burst{0.0, 2 * kParallelBlockRows + 301}, Burst{0.05, 999}};
      s.rate = 1234.5;
      const Emitter emitter(s, 1, 60);
      for (const std::uint32_t count : {1u, 2u, 3u, 5u}) {
        for (std::uint32_t index = 0; index < count; ++index) {
          const Shard shard{index, count};
          for (const int threads : {1, 3}) {
            ParticlePool pool(1'000'000);
            tbb::task_arena arena(threads);
            for (std::int64_t tick = 0; tick < 5; ++tick)
              arena.execute([&] { emitter.emit(pool, 31, tick, shard); });
            const std::uint64_t made = emitter.serialBefore(5);
            ASSERT_EQ(pool.nextId(), made);
            std::uint64_t owned = 0;
            for (std::uint64_t serial = 0; serial < made; ++serial)
              owned += shard.ownerOfSerial(1, serial) == index;
            ASSERT_EQ(pool.size(), owned) << c.name << ", shard " << shard.text();
            for (std::size_t row = 0; row < pool.size(); ++row) {
              const std::uint64_t serial = pool.id()[row];
              ASSERT_EQ(shard.ownerOfSerial(1, serial), index) << c.name << ", row " << row;
              const ParticleInit want = emitter.sample(31, serial);
              ASSERT_TRUE(test::sameBits(rowOf(pool, row), want))
                  << isaName(isa) << ", " << c.name << ", shard " << shard.text() << ", " << threads
                  << " threads, row " << row << ", serial " << serial << ": got "
                  << describe(rowOf(pool, row)) << ", want " << describe(want);
            }
          }
        }
      }
    }
  }
}

// emit() writes rows by columns (spawnRows, then ParticlePool::finishRows), where a spawn sets a
// row (setRow): the previous position, the acceleration and the pool's flags must come out as
// setRow() leaves them, for pools with and without those columns and for finite and infinite
// lifetimes and masses.
TEST(EmitterBatch, EmitFinishesRowsAsSetRowDoes) {
  const double inf = std::numeric_limits<double>::infinity();
  for (const bool history : {false, true}) {
    for (const double lifetime : {2.0, inf}) {
      for (const double mass : {0.7, inf}) {
        EmitterSettings s = moving(BoxShape{Eigen::Vector3d(2.0, 1.0, 0.25)}, 30.0);
        s.lifetime = lifetime;
        s.lifetimeJitter = 0.0;
        s.mass = mass;
        s.bursts = {Burst{0.0, kParallelBlockRows + 77}};
        const Emitter emitter(s, 0, 60);
        ParticlePool emitted(100'000), set(100'000);
        for (ParticlePool* pool : {&emitted, &set}) {
          if (history) {
            pool->keepPrevious();
            pool->keepAcceleration();
          }
        }
        // Stale values where the new rows go: finishRows() must overwrite them.
        emitted.appendRows(kParallelBlockRows + 77, 0);
        for (int c = 0; c < 3 && history; ++c) {
          emitted.previousPosition()[c].setConstant(-7.0f);
          emitted.acceleration()[c].setConstant(9.0f);
        }
        emitted.dropNewest(0, 0);
        emitter.emit(emitted, 5, 0);
        const std::size_t first = set.appendRows(kParallelBlockRows + 77, 0);
        for (std::size_t k = 0; k < set.size(); ++k) set.setRow(first + k, emitter.sample(5, k));
        const std::string label = std::string(history ? "history" : "no history") + ", lifetime " +
                                  std::to_string(lifetime) + ", mass " + std::to_string(mass);
        ASSERT_EQ(emitted.size(), set.size()) << label;
        EXPECT_EQ(emitted.mayHaveFiniteLifetimes(), set.mayHaveFiniteLifetimes()) << label;
        EXPECT_EQ(emitted.mayHaveFiniteLifetimes(), lifetime != inf) << label;
        EXPECT_EQ(emitted.mayHavePinned(), set.mayHavePinned()) << label;
        EXPECT_EQ(emitted.mayHavePinned(), mass == inf) << label;
        for (std::size_t row = 0; row < set.size(); ++row) {
          ASSERT_TRUE(test::sameBits(rowOf(emitted, row), rowOf(set, row)))
              << label << ", row " << row;
          for (int c = 0; c < 3 && history; ++c) {
            ASSERT_EQ(emitted.previousPosition()[c][row], set.position()[c][row]) << label;
            ASSERT_EQ(emitted.acceleration()[c][row], 0.0f) << label;
          }
        }
      }
    }
  }
}

}  // namespace
}  // namespace tickfx
