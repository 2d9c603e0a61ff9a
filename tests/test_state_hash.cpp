// The state hash: equal for equal runs, different for a state that differs by one bit.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "CoreTestSupport.h"
#include "particles/StateHash.h"

namespace tickfx {
namespace {

TEST(StateHash, TwoIndependentRunsGiveTheSameHash) {
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

// Every float column of every row is in the hash: flipping its lowest bit or its sign (+0 and −0
// included) changes the hash, and flipping it back restores it.
TEST(StateHash, OneFlippedBitOfOneParticleChangesIt) {
  const auto system = test::referenceSystem(test::referenceSettings("velocity_verlet"));
  system->stepTicks(90);
  ParticlePool& pool = system->pool();
  const std::uint64_t original = stateHash(pool);
  const auto last = static_cast<Eigen::Index>(pool.size() - 1);
  std::vector<FloatColumn*> columns{&pool.age(), &pool.lifetime(), &pool.mass(),
                                    &pool.inverseMass()};
  for (Vec3Column* v :
       {&pool.position(), &pool.velocity(), &pool.previousPosition(), &pool.acceleration()}) {
    for (int c = 0; c < 3; ++c) columns.push_back(&(*v)[c]);
  }
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

TEST(StateHash, HexIsSixteenLowercaseDigits) {
  EXPECT_EQ(hashToHex(0), "0000000000000000");
  EXPECT_EQ(hashToHex(0x0123456789abcdefULL), "0123456789abcdef");
  EXPECT_EQ(hashToHex(~std::uint64_t{0}), "ffffffffffffffff");
}

}  // namespace
}  // namespace tickfx
