// The state hash: equal for equal runs, different for a state that differs by one bit.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "CoreTestSupport.h"
#include "particles/StateHash.h"

namespace tickfx {
namespace {

// A regression guard: the same code path run twice in one process, so equal hashes show only that
// nothing outside the effect (uninitialised memory, a static, the allocator) leaks into the state;
// one more tick must change the hash. Frames, threads and builds are tested elsewhere.
TEST(StateHash, SamePathTwiceGivesTheSameHashRegressionGuard) {
  for (const std::string& name : integratorNames()) {
    const auto a = test::referenceSystem(test::referenceSettings(name));
    const auto b = test::referenceSystem(test::referenceSettings(name));
    a->stepTicks(150);
    b->stepTicks(150);
    ASSERT_GT(a->pool().size(), 100u);
    EXPECT_EQ(stateHash(a->pool()), stateHash(b->pool())) << name;
    b->step();
    EXPECT_NE(stateHash(a->pool()), stateHash(b->pool())) << name;
  }
}

// More rows than one parallel block: the bits may not depend on the thread count.
TEST(StateHash, ThreadCountDoesNotChangeTheState) {
  EmitterSettings e = test::referenceEmitter();
  e.rate = 40'000.0;
  e.lifetime = 10.0;
  std::vector<std::uint64_t> hashes;
  for (int threads : {1, 2}) {
    SystemSettings settings = test::referenceSettings("rk4");
    settings.threads = threads;
    ParticleSystem system(settings, {e}, test::referenceForces());
    system.stepTicks(30);  // 20000 particles
    ASSERT_EQ(system.pool().size(), 20'000u);
    hashes.push_back(stateHash(system.pool()));
  }
  EXPECT_EQ(hashes[0], hashes[1]);
}

// Flips bits of `columns` (and an id and a birth tick) of three rows of `pool`, expecting each
// flip to change the hash and its undoing to restore it.
void expectEveryBitCounts(ParticlePool& pool, const std::vector<FloatColumn*>& columns);

// Every float column of every row is in the hash: flipping its lowest bit or its sign (+0 and −0
// included) changes the hash, and flipping it back restores it.
TEST(StateHash, OneFlippedBitOfOneParticleChangesIt) {
  // Velocity Verlet keeps an acceleration; position Verlet's previous position is state.
  for (const char* integrator : {"velocity_verlet", "position_verlet"}) {
    SCOPED_TRACE(integrator);
    const auto system = test::referenceSystem(test::referenceSettings(integrator));
    system->stepTicks(90);
    ParticlePool& pool = system->editPool();
    std::vector<FloatColumn*> columns{&pool.lifetime(), &pool.mass()};
    for (Vec3Column* v :
         {&pool.position(), &pool.velocity(),
          pool.keepsAcceleration() ? &pool.acceleration() : &pool.previousPosition()}) {
      for (int c = 0; c < 3; ++c) columns.push_back(&(*v)[c]);
    }
    expectEveryBitCounts(pool, columns);
  }
}

// Elsewhere the previous position is what a frame between ticks interpolates from, not state:
// the state after tick k is the same whatever frames drove it, and so is its hash.
TEST(StateHash, APreviousPositionThatIsNotStateIsNotHashed) {
  const auto kept = test::referenceSystem(test::referenceSettings("rk4"));
  const auto plain = test::referenceSystem(test::referenceSettings("rk4"));
  kept->setKeepPreviousPositions(true);
  kept->stepTicks(40);
  plain->stepTicks(40);
  ASSERT_TRUE(kept->pool().keepsPrevious());
  EXPECT_FALSE(plain->pool().keepsPrevious());
  EXPECT_EQ(stateHash(*kept), stateHash(*plain));
  ParticlePool& pool = kept->editPool();
  const std::uint64_t original = stateHash(pool);
  pool.previousPosition().x[3] = -pool.previousPosition().x[3];
  EXPECT_EQ(stateHash(pool), original);
}

void expectEveryBitCounts(ParticlePool& pool, const std::vector<FloatColumn*>& columns) {
  const std::uint64_t original = stateHash(pool);
  const auto last = static_cast<Eigen::Index>(pool.size() - 1);
  for (std::size_t k = 0; k < columns.size(); ++k) {
    for (Eigen::Index row : {Eigen::Index{0}, last / 2, last}) {
      for (std::uint32_t bit : {0u, 31u}) {
        float& value = (*columns[k])[row];
        const float saved = value;
        value = test::withBits(test::bitsOf(saved) ^ (1u << bit));
        EXPECT_NE(stateHash(pool), original)
            << "column " << k << ", row " << row << ", bit " << bit;
        value = saved;
        ASSERT_EQ(stateHash(pool), original);
      }
    }
  }
  pool.id()[1] += 1;
  EXPECT_NE(stateHash(pool), original);
  pool.id()[1] -= 1;
  pool.birthTick()[2] += 1;
  EXPECT_NE(stateHash(pool), original);
  pool.birthTick()[2] -= 1;
  EXPECT_EQ(stateHash(pool), original);
}

// What a hash log uses to name a difference: a flipped bit changes its own column's hash and no
// other, and the row's bits show the value that changed.
TEST(StateHash, ColumnHashesNameTheColumnThatChanged) {
  const auto system = test::referenceSystem(test::referenceSettings("velocity_verlet"));
  system->stepTicks(90);
  ParticlePool& pool = system->editPool();
  const std::vector<std::string> names = stateColumnNames(pool);
  ASSERT_EQ(names.size(), 3u + 12u + 4u + pool.attributeCount());
  EXPECT_EQ(names[0], "counters");
  EXPECT_EQ(names[4], "position.y");
  EXPECT_EQ(names[14], "acceleration.z");
  EXPECT_EQ(names[18], "inverse_mass");
  const std::vector<std::uint64_t> original = stateColumnHashes(pool);
  ASSERT_EQ(original.size(), names.size());
  const std::vector<std::uint64_t> row = stateRowBits(pool, 3);
  ASSERT_EQ(row.size(), names.size() - 1);
  EXPECT_EQ(row[0], pool.id()[3]);
  EXPECT_EQ(row[3], test::bitsOf(pool.position().y[3]));

  pool.position().y[3] = test::withBits(test::bitsOf(pool.position().y[3]) ^ 1u);
  const std::vector<std::uint64_t> changed = stateColumnHashes(pool);
  for (std::size_t c = 0; c < names.size(); ++c) {
    if (names[c] == "position.y") {
      EXPECT_NE(changed[c], original[c]);
    } else {
      EXPECT_EQ(changed[c], original[c]) << names[c];
    }
  }
  EXPECT_EQ(stateRowBits(pool, 3)[3], row[3] ^ 1u);
}

// The hash function itself is part of the format: hash logs and golden hashes recorded by one
// version are compared with another's, so it must never change unnoticed. Two particles with
// distinct values in every column (a particle's z differs from its x and y, so hashing a column
// twice or skipping one shows) have this hash and these column hashes for good (they moved once,
// in 0.3.0, when columns came to be hashed in blocks: docs/determinism.md).
TEST(StateHash, AKnownStateKeepsItsHashAcrossVersions) {
  ParticlePool pool(4);
  pool.keepPrevious(/*asState=*/true);  // as position Verlet's: every column in the hash
  ParticleInit a;
  a.position = Eigen::Vector3f(0.25f, -1.5f, 3.0f);
  a.velocity = Eigen::Vector3f(-0.125f, 2.0f, 0.75f);
  a.lifetime = 2.5f;
  a.mass = 0.5f;
  pool.spawn(a, 3);
  ParticleInit b;
  b.position = Eigen::Vector3f(1.0f, 2.0f, -4.0f);
  b.velocity = Eigen::Vector3f(0.0f, -0.0f, 5.0f);
  pool.spawn(b, 7);
  EXPECT_EQ(hashToHex(stateHash(pool)), "4ff37249608e0b77");
  const std::vector<std::string> names = stateColumnNames(pool);
  const std::vector<std::uint64_t> columns = stateColumnHashes(pool);
  ASSERT_EQ(names.size(), columns.size());
  std::string all;
  for (std::size_t c = 0; c < names.size(); ++c)
    all += names[c] + "=" + hashToHex(columns[c]) + " ";
  EXPECT_EQ(all,
            "counters=8298a17d732b38b7 "
            "id=d14b8668775ff1a0 "
            "birth_tick=7c7669deb66173a7 "
            "position.x=c5a672558d936b2d "
            "position.y=d00521c44f07081e "
            "position.z=b049df6625a551ef "
            "velocity.x=e1b5b6e27216cda9 "
            "velocity.y=58d194cc3334e994 "
            "velocity.z=d2095ee817c13c5a "
            "previous_position.x=c5a672558d936b2d "
            "previous_position.y=d00521c44f07081e "
            "previous_position.z=b049df6625a551ef "
            "acceleration.x=4f201c59cb68c644 "
            "acceleration.y=4f201c59cb68c644 "
            "acceleration.z=4f201c59cb68c644 "
            "age=4f201c59cb68c644 "
            "lifetime=025735b5297c9bde "
            "mass=8620927b1f29bfb5 "
            "inverse_mass=b1c4a2bc682b2b06 ");
}

TEST(StateHash, HexIsSixteenLowercaseDigits) {
  EXPECT_EQ(hashToHex(0), "0000000000000000");
  EXPECT_EQ(hashToHex(0x0123456789abcdefULL), "0123456789abcdef");
  EXPECT_EQ(hashToHex(~std::uint64_t{0}), "ffffffffffffffff");
}

}  // namespace
}  // namespace tickfx
