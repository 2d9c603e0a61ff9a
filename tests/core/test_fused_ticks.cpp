// A frame of several ticks under local forces runs block by block, each block through all the
// frame's ticks (fused). It must give the rows, ids and bits of the ticks run one by one, with
// births and deaths inside the frame, for every integrator and thread count, and stop at the same
// tick when the state goes non-finite.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "CoreTestSupport.h"
#include "ForcedIsa.h"
#include "fields/AnchorSpring.h"
#include "fields/Gravity.h"
#include "fields/LinearDrag.h"
#include "fields/PeriodicWind.h"
#include "fields/vdb/AnalyticField.h"
#include "particles/Clock.h"
#include "particles/ParticleSystem.h"
#include "particles/StateHash.h"

namespace tickfx {
namespace {

constexpr std::int64_t kRate = 60;

// A frame of `ticks` ticks at kRate.
Flicks frameOf(std::int64_t ticks) { return ticks * (kFlicksPerSecond / kRate); }

// The scheduling tests' crowd, with a burst in the middle of a frame and shorter lives (deaths
// inside frames from the first ones on).
EmitterSettings busyEmitter() {
  EmitterSettings e = test::crowdEmitter();
  e.bursts.push_back({0.3, 9000});
  e.lifetime = 0.2;
  return e;
}

ForceSet localForces() {
  ForceSet forces = test::gravityAndWind();
  forces.add(std::make_unique<LinearDrag>(0.3f, Eigen::Vector3f(1.0f, 0.0f, 0.0f)));
  forces.add(std::make_unique<AnchorSpring>(Eigen::Vector3f(0.0f, 2.0f, 0.0f), 2.0f, 0.1f));
  return forces;
}

ForceSet advectingForces() {
  ForceSet forces;
  forces.add(std::make_unique<AnalyticForce>(AnalyticField::curlNoise(7, 2.0, 1.5, 4, 1.0),
                                             AnalyticForce::Mode::Advect, 1.0f));
  return forces;
}

std::unique_ptr<ParticleSystem> makeSystem(const std::string& integrator, int threads,
                                           ForceSet forces, bool oneByOne) {
  SystemSettings settings;
  settings.stepRateHz = kRate;
  settings.integrator = integrator;
  settings.seed = 41;
  settings.threads = threads;
  auto system =
      std::make_unique<ParticleSystem>(settings, std::vector{busyEmitter()}, std::move(forces));
  // A tick observer sees every tick: the system then never fuses.
  if (oneByOne) system->setTickObserver([](const ParticleSystem&) {});
  return system;
}

template <typename Column>
bool sameBits(const Column& a, const Column& b, std::size_t rows) {
  return std::memcmp(a.data(), b.data(), rows * sizeof(a.data()[0])) == 0;
}

bool sameBits(const Vec3Column& a, const Vec3Column& b, std::size_t rows) {
  return sameBits(a.x, b.x, rows) && sameBits(a.y, b.y, rows) && sameBits(a.z, b.z, rows);
}

// Every column of the state and every render copy, bit for bit.
void expectSameState(const ParticleSystem& fused, const ParticleSystem& reference) {
  ASSERT_EQ(fused.tickCount(), reference.tickCount());
  const ParticlePool& a = fused.pool();
  const ParticlePool& b = reference.pool();
  ASSERT_EQ(a.size(), b.size()) << "at tick " << reference.tickCount();
  const std::size_t n = a.size();
  EXPECT_TRUE(sameBits(a.id(), b.id(), n));
  EXPECT_TRUE(sameBits(a.position(), b.position(), n));
  EXPECT_TRUE(sameBits(a.velocity(), b.velocity(), n));
  // Kept by the same ticks (a frame's last, when it falls between ticks), with the same bits.
  EXPECT_EQ(fused.previousPositionsKept(), reference.previousPositionsKept());
  if (fused.previousPositionsKept() && reference.previousPositionsKept()) {
    EXPECT_TRUE(sameBits(a.previousPosition(), b.previousPosition(), n));
  }
  EXPECT_TRUE(sameBits(test::agesOf(a), test::agesOf(b), n));
  EXPECT_TRUE(sameBits(a.lifetime(), b.lifetime(), n));
  EXPECT_EQ(a.keepsAcceleration(), b.keepsAcceleration());
  if (a.keepsAcceleration()) {
    EXPECT_TRUE(sameBits(a.acceleration(), b.acceleration(), n));
  }
  EXPECT_EQ(a.nextId(), b.nextId());
  EXPECT_EQ(a.droppedSpawns(), b.droppedSpawns());
  EXPECT_EQ(stateHash(a), stateHash(b));
  Vec3Column pa, pb, va, vb;
  fused.renderPositions(pa);
  reference.renderPositions(pb);
  fused.renderVelocities(va);
  reference.renderVelocities(vb);
  EXPECT_TRUE(sameBits(pa, pb, n));
  EXPECT_TRUE(sameBits(va, vb, n));
  FloatColumn aa, ab;
  fused.renderAges(aa);
  reference.renderAges(ab);
  EXPECT_TRUE(sameBits(aa, ab, n));
}

// Frames of 4, 3, 1, 2 and 5 ticks, then frames between ticks (2.5 ticks: interpolated copies).
const std::vector<Flicks>& frames() {
  static const std::vector<Flicks> f = [] {
    std::vector<Flicks> out;
    for (int repeat = 0; repeat < 3; ++repeat) {
      for (std::int64_t ticks : {4, 3, 1, 2, 5}) out.push_back(frameOf(ticks));
    }
    for (int i = 0; i < 4; ++i) out.push_back(frameOf(5) / 2);
    return out;
  }();
  return f;
}

// Returns the fused systems at the run's end (to be asked how they ran), none after a failure.
std::vector<std::unique_ptr<ParticleSystem>> expectFusedMatchesOneByOne(
    const std::string& integrator, ForceSet (*forces)(), const std::vector<int>& threadCounts) {
  const auto reference = makeSystem(integrator, 1, forces(), true);
  std::vector<std::unique_ptr<ParticleSystem>> fused;
  for (int threads : threadCounts)
    fused.push_back(makeSystem(integrator, threads, forces(), false));
  std::size_t crowd = 0;
  std::int64_t severalTicks = 0;  // frames a system may fuse
  for (const Flicks frame : frames()) {
    if (reference->advance(frame).ticks >= 2) ++severalTicks;
    crowd = std::max(crowd, reference->pool().size());
    for (auto& system : fused) {
      system->advance(frame);
      SCOPED_TRACE("threads " + std::to_string(system->settings().threads));
      expectSameState(*system, *reference);
      if (::testing::Test::HasFailure()) return {};
    }
  }
  EXPECT_EQ(reference->fusedTicks(), 0);
  for (auto& system : fused) EXPECT_GT(system->fusedTicks(), 0);
  EXPECT_GT(crowd, 20000u);  // the test moved several blocks of rows, not a few survivors
  EXPECT_GT(severalTicks, 10);
  return fused;
}

class FusedFrames : public ::testing::TestWithParam<std::string> {};

TEST_P(FusedFrames, GiveTheRowsIdsAndBitsOfTicksOneByOne) {
  expectFusedMatchesOneByOne(GetParam(), &localForces, {1, 2, 3});
}

TEST_P(FusedFrames, GiveTheBitsOfTicksOneByOneUnderAdvection) {
  expectFusedMatchesOneByOne(GetParam(), &advectingForces, {2});
}

TEST(FusedFrames, RunEveryFrameOfSeveralTicksAndNoOther) {
  const auto system = makeSystem("semi_implicit_euler", 2, localForces(), false);
  std::int64_t expected = 0;
  for (const Flicks frame : frames()) {
    const AdvanceResult r = system->advance(frame);
    if (r.ticks >= 2) expected += r.ticks;
  }
  EXPECT_EQ(system->fusedTicks(), expected);
  EXPECT_EQ(expected, 3 * (4 + 3 + 2 + 5) + (2 + 3 + 2 + 3));  // 2.5-tick frames: 2, 3, 2, 3
}

// A stiff spring at 60 Hz (ω = 1000 rad/s, ω·dt ≈ 17, past every scheme's stability limit):
// each tick multiplies the amplitude manyfold, so the state overflows after some ticks. Going back
// to the frame's start must restore what each scheme reads (position Verlet's previous position,
// velocity Verlet's acceleration).
std::unique_ptr<ParticleSystem> unstableSystem(const std::string& integrator, bool oneByOne) {
  SystemSettings settings;
  settings.stepRateHz = kRate;
  settings.integrator = integrator;
  settings.seed = 5;
  settings.threads = 2;
  EmitterSettings e = busyEmitter();
  e.lifetime = 100.0;
  // Past the 2^18 rows from which a fused frame's copy of its start bypasses the caches.
  e.bursts = {{0.0, 300000}, {0.3, 9000}};
  ForceSet forces;
  forces.add(std::make_unique<AnchorSpring>(Eigen::Vector3f(0.0f, 2.0f, 0.0f), 1.0e6f, 0.0f));
  auto system = std::make_unique<ParticleSystem>(settings, std::vector{e}, std::move(forces));
  if (oneByOne) system->setTickObserver([](const ParticleSystem&) {});
  return system;
}

// The stiff spring's run in frames whose stop falls inside one: the fused run must stop at the
// tick of the run one by one, naming the same particles, with its state.
void expectStopOfTicksOneByOne(const std::string& integrator) {
  // Frames of a length that puts the stop inside a frame, not on its last tick.
  const auto probe = unstableSystem(integrator, true);
  for (int tick = 0; tick < 1000 && !probe->nonfiniteStop(); ++tick) probe->step();
  ASSERT_TRUE(probe->nonfiniteStop().has_value()) << "the spring never blew up";
  const std::int64_t stopTick = probe->nonfiniteStop()->tick;
  std::int64_t frame = 3;
  while (stopTick % frame == 0) ++frame;

  const auto fused = unstableSystem(integrator, false);
  const auto reference = unstableSystem(integrator, true);
  while (!reference->nonfiniteStop()) {
    reference->advance(frameOf(frame));
    fused->advance(frameOf(frame));
  }
  ASSERT_TRUE(fused->nonfiniteStop().has_value());
  EXPECT_EQ(reference->nonfiniteStop()->tick, stopTick);
  EXPECT_EQ(fused->nonfiniteStop()->tick, stopTick);
  EXPECT_EQ(fused->nonfiniteStop()->particles, reference->nonfiniteStop()->particles);
  EXPECT_EQ(fused->nonfiniteStop()->firstIds, reference->nonfiniteStop()->firstIds);
  EXPECT_GT(fused->fusedTicks(), 0);
  expectSameState(*fused, *reference);
}

TEST_P(FusedFrames, StopAtTheTickThatWentNonFiniteWithItsState) {
  expectStopOfTicksOneByOne(GetParam());
}

// The copy of a frame's start is written by each path's own stores (particles/Isa.h): every path
// must restore the state it saved, for the schemes that save the previous position and the
// acceleration too. The default path is the one StopAtTheTickThatWentNonFiniteWithItsState runs.
TEST(FusedFrames, StopWithTheStateOneByOneOnEveryOtherPath) {
  const Isa widest = activeIsa();
  for (const Isa isa : test::isasHere()) {
    if (isa == widest) continue;
    const ForcedIsa forced(isa);
    for (const char* integrator : {"semi_implicit_euler", "position_verlet", "velocity_verlet"}) {
      SCOPED_TRACE(std::string(isaName(isa)) + ", " + integrator);
      expectStopOfTicksOneByOne(integrator);
    }
  }
}

// Gravity, a wind and a drag: the one pass's forms, under which every scheme bounds its tick
// (Integrator::boundTick), so that a frame is proven finite before it runs.
ForceSet formForces() {
  ForceSet forces = test::gravityAndWind();
  forces.add(std::make_unique<LinearDrag>(0.3f, Eigen::Vector3f(1.0f, 0.0f, 0.0f)));
  return forces;
}

// Under NonfinitePolicy::Stop (the default) a frame proven finite copies nothing of its start,
// and gives the bits of the ticks one by one all the same, births and deaths inside frames and
// the two Verlets' third columns included.
TEST_P(FusedFrames, ProvenFiniteCopyNothingWithTheBitsOfTicksOneByOne) {
  const std::string& integrator = GetParam();
  const auto fused = expectFusedMatchesOneByOne(integrator, &formForces, {3});
  if (HasFailure()) return;
  EXPECT_EQ(fused.at(0)->framesCopied(), 0);
  // Under a spring (not the forms) every fused frame copies its start.
  const auto springy = makeSystem(integrator, 2, localForces(), false);
  std::int64_t springyFrames = 0;
  for (const Flicks frame : frames()) springyFrames += springy->advance(frame).ticks >= 2 ? 1 : 0;
  EXPECT_EQ(springy->framesCopied(), springyFrames);
}

// A state a host writes near the float limit (after proven frames, whose measured bounds the
// edit must void) is not proven: its frames copy their start, and the run stops at the tick the
// ticks one by one stop at, inside a frame, with their state.
TEST_P(FusedFrames, AStateNearTheFloatLimitIsNotProvenAndStopsAtItsTick) {
  const std::string& integrator = GetParam();
  const auto edit = [](ParticleSystem& system) {
    ParticlePool& pool = system.editPool();
    // The newest particle, which lives on for some ticks: p + v·dt overflows in the next ones.
    const auto row = static_cast<Eigen::Index>(pool.size() - 1);
    pool.position().x[row] = 3.3e38f;
    pool.velocity().x[row] = 3.0e38f;
  };
  const auto probe = makeSystem(integrator, 1, formForces(), true);
  for (int i = 0; i < 3; ++i) probe->advance(frameOf(4));
  edit(*probe);
  const std::int64_t edited = probe->tickCount();
  while (!probe->nonfiniteStop() && probe->tickCount() < edited + 100) probe->step();
  ASSERT_TRUE(probe->nonfiniteStop().has_value());
  const std::int64_t after = probe->nonfiniteStop()->tick - edited;
  std::int64_t frame = 3;
  while (after % frame == 0) ++frame;

  const auto fused = makeSystem(integrator, 2, formForces(), false);
  const auto reference = makeSystem(integrator, 2, formForces(), true);
  for (int i = 0; i < 3; ++i) {
    fused->advance(frameOf(4));
    reference->advance(frameOf(4));
  }
  const std::int64_t copied = fused->framesCopied();
  EXPECT_EQ(copied, 0);
  edit(*fused);
  edit(*reference);
  while (!reference->nonfiniteStop()) {
    reference->advance(frameOf(frame));
    fused->advance(frameOf(frame));
  }
  ASSERT_TRUE(fused->nonfiniteStop().has_value());
  EXPECT_EQ(fused->nonfiniteStop()->tick, probe->nonfiniteStop()->tick);
  EXPECT_EQ(fused->nonfiniteStop()->particles, reference->nonfiniteStop()->particles);
  EXPECT_EQ(fused->nonfiniteStop()->firstIds, reference->nonfiniteStop()->firstIds);
  EXPECT_GT(fused->framesCopied(), copied);
  expectSameState(*fused, *reference);
}

TEST(FusedFrames, AFrameThatMayFillThePoolRunsTickByTick) {
  const auto make = [](bool oneByOne) {
    SystemSettings settings;
    settings.stepRateHz = kRate;
    settings.seed = 3;
    settings.maxParticles = 20300;  // the first frame fits; the rate then meets the cap
    auto system =
        std::make_unique<ParticleSystem>(settings, std::vector{busyEmitter()}, localForces());
    if (oneByOne) system->setTickObserver([](const ParticleSystem&) {});
    return system;
  };
  const auto fused = make(false);
  const auto reference = make(true);
  for (int frame = 0; frame < 12; ++frame) {
    fused->advance(frameOf(4));
    reference->advance(frameOf(4));
    expectSameState(*fused, *reference);
  }
  EXPECT_GT(reference->pool().droppedSpawns(), 0u) << "the test wants refused spawns";
  EXPECT_GT(fused->fusedTicks(), 0);       // the first frame fits
  EXPECT_LT(fused->fusedTicks(), 12 * 4);  // the frames at the cap do not
}

INSTANTIATE_TEST_SUITE_P(AllIntegrators, FusedFrames, ::testing::ValuesIn(integratorNames()),
                         [](const ::testing::TestParamInfo<std::string>& p) { return p.param; });

}  // namespace
}  // namespace tickfx
