// The scheduling of an integrator's passes (fused tiles or split whole-pool passes, any thread
// count) must not change a single bit of the state.
#include <gtest/gtest.h>

#include <memory>
#include <stdexcept>

#include "CoreTestSupport.h"
#include "ForcedIsa.h"
#include "fields/AnchorSpring.h"
#include "fields/Gravity.h"
#include "fields/LinearDrag.h"
#include "fields/PeriodicWind.h"
#include "integrators/StagePasses.h"
#include "particles/ParticleSystem.h"
#include "particles/StateHash.h"

namespace tickfx {
namespace {

// Adds nothing, but claims to read other rows: the integrators must then run split passes.
class NonLocalNothing final : public ForceModule {
 public:
  std::string_view typeName() const override { return "non_local_nothing"; }
  bool isLocal() const override { return false; }
  void accumulate(const ForceInput&, RowRange, Vec3Rows&) const override {}
};

std::uint64_t runHash(const std::string& integrator, int threads, bool split,
                      NonfinitePolicy nonfinite = NonfinitePolicy::Stop) {
  SystemSettings settings;
  settings.nonfinite = nonfinite;
  settings.stepRateHz = 60;
  settings.integrator = integrator;
  settings.seed = 99;
  settings.threads = threads;
  ForceSet forces = test::gravityAndWind();
  forces.add(std::make_unique<LinearDrag>(0.3f, Eigen::Vector3f(1.0f, 0.0f, 0.0f)));
  forces.add(std::make_unique<AnchorSpring>(Eigen::Vector3f(0.0f, 2.0f, 0.0f), 2.0f, 0.1f));
  if (split) forces.add(std::make_unique<NonLocalNothing>());
  ParticleSystem system(settings, {test::crowdEmitter()}, std::move(forces));
  system.stepTicks(30);
  return stateHash(system.pool());
}

// Gravity and wind, with or without a drag: what every scheme forms in its update loop
// (ForceSet::uniformAndDrag, UniformAndDragRows.h). With a module that adds nothing but claims to
// read other rows, the same forces take the force passes and the split passes instead. Ticks one
// by one, then fused frames of 4 ticks (the rows new each tick start the Verlets' histories).
std::uint64_t uniformAndDragHash(const std::string& integrator, int threads, bool drag,
                                 bool generic) {
  SystemSettings settings;
  settings.stepRateHz = 60;
  settings.integrator = integrator;
  settings.seed = 17;
  settings.threads = threads;
  ForceSet forces = test::gravityAndWind();
  if (drag) forces.add(std::make_unique<LinearDrag>(0.3f, Eigen::Vector3f(1.0f, -0.5f, 0.0f)));
  if (generic) forces.add(std::make_unique<NonLocalNothing>());
  ParticleSystem system(settings, {test::crowdEmitter()}, std::move(forces));
  for (int tick = 0; tick < 20; ++tick) system.step();
  system.stepTicks(20);
  return stateHash(system.pool());
}

class UniformAndDrag : public ::testing::TestWithParam<std::string> {};

TEST_P(UniformAndDrag, OnePassGivesTheBitsOfTheForcePasses) {
  for (const bool drag : {true, false}) {
    const std::uint64_t reference = uniformAndDragHash(GetParam(), 1, drag, true);
    EXPECT_EQ(uniformAndDragHash(GetParam(), 1, drag, false), reference) << "drag " << drag;
    EXPECT_EQ(uniformAndDragHash(GetParam(), 2, drag, false), reference) << "drag " << drag;
  }
  EXPECT_NE(uniformAndDragHash(GetParam(), 1, true, false),
            uniformAndDragHash(GetParam(), 1, false, false));
}

INSTANTIATE_TEST_SUITE_P(AllIntegrators, UniformAndDrag, ::testing::ValuesIn(integratorNames()),
                         [](const ::testing::TestParamInfo<std::string>& p) { return p.param; });

class PassScheduling : public ::testing::TestWithParam<std::string> {};

TEST_P(PassScheduling, FusedSplitAndThreadCountsGiveTheSameBits) {
  const std::uint64_t reference = runHash(GetParam(), 1, false);
  EXPECT_EQ(runHash(GetParam(), 2, false), reference);
  EXPECT_EQ(runHash(GetParam(), 3, false), reference);
  EXPECT_EQ(runHash(GetParam(), 1, true), reference);
  EXPECT_EQ(runHash(GetParam(), 2, true), reference);
}

INSTANTIATE_TEST_SUITE_P(AllIntegrators, PassScheduling, ::testing::ValuesIn(integratorNames()),
                         [](const ::testing::TestParamInfo<std::string>& p) { return p.param; });

// The update loops' AVX2 clones (CheckedRows.h) give the baseline loops' bits, for every scheme,
// in its one pass (with and without a drag), its force passes, its split passes, checked by sums,
// by exceptions and unchecked, on 1 and 3 threads (tiles cut into component blocks and tails).
class EveryIsa : public ::testing::TestWithParam<std::string> {};

TEST_P(EveryIsa, GivesTheBitsOfTheBaselineLoops) {
  struct Run {
    std::uint64_t onePassDrag, onePass, generic, split, unchecked, threads;
  };
  const auto run = [&] {
    return Run{uniformAndDragHash(GetParam(), 1, true, false),
               uniformAndDragHash(GetParam(), 1, false, false),
               uniformAndDragHash(GetParam(), 1, true, true),
               runHash(GetParam(), 1, true),
               runHash(GetParam(), 1, false, NonfinitePolicy::Keep),
               runHash(GetParam(), 3, false)};
  };
  Run baseline{};
  {
    const ForcedIsa forced(Isa::Baseline);
    baseline = run();
  }
  for (const Isa isa : test::isasHere()) {
    if (isa == Isa::Baseline) continue;  // the reference itself
    const ForcedIsa forced(isa);
    const Run r = run();
    EXPECT_EQ(r.onePassDrag, baseline.onePassDrag) << isaName(isa);
    EXPECT_EQ(r.onePass, baseline.onePass) << isaName(isa);
    EXPECT_EQ(r.generic, baseline.generic) << isaName(isa);
    EXPECT_EQ(r.split, baseline.split) << isaName(isa);
    EXPECT_EQ(r.unchecked, baseline.unchecked) << isaName(isa);
    EXPECT_EQ(r.threads, baseline.threads) << isaName(isa);
  }
}

INSTANTIATE_TEST_SUITE_P(AllIntegrators, EveryIsa, ::testing::ValuesIn(integratorNames()),
                         [](const ::testing::TestParamInfo<std::string>& p) { return p.param; });

// The fused passes keep every stage column of a tile in one stack buffer of kMaxColumns columns:
// a scheme may ask for 0 to kMaxColumns of them, and no more.
TEST(StageScratch, HoldsZeroToMaxColumnsAndRefusesMore) {
  EXPECT_EQ(StageScratch(0).count(), 0);
  EXPECT_EQ(StageScratch(StageScratch::kMaxColumns).count(), StageScratch::kMaxColumns);
  EXPECT_THROW(StageScratch(StageScratch::kMaxColumns + 1), std::invalid_argument);
  EXPECT_THROW(StageScratch(-1), std::invalid_argument);
}

}  // namespace
}  // namespace tickfx
