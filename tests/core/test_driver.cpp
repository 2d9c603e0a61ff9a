// The fixed-step driver and the system it drives: the state after T seconds is a function of T
// alone, not of the frames that got there.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "CoreTestSupport.h"
#include "particles/StateHash.h"

namespace tickfx {
namespace {

constexpr Flicks kSecond = kFlicksPerSecond;

// floor(T · rate / kFlicksPerSecond) in exact integers.
std::int64_t ticksIn(Flicks total, std::int64_t rate) {
  return static_cast<std::int64_t>(static_cast<__int128>(total) * rate / kFlicksPerSecond);
}

// The exact fraction of a tick left over after `total` flicks.
double fractionIn(Flicks total, std::int64_t rate) {
  const __int128 units = static_cast<__int128>(total) * rate;
  return static_cast<double>(static_cast<std::int64_t>(units % kFlicksPerSecond)) /
         static_cast<double>(kFlicksPerSecond);
}

// α is one float division of exact integers: within 2 roundings (≤ 2^-23 absolute below 1).
constexpr double kAlphaTolerance = 0x1p-23;

TEST(Clock, CommonFrameRatesAreWholeFlicks) {
  EXPECT_EQ(frameDuration(FrameRate{24, 1}), 29'400'000);
  EXPECT_EQ(frameDuration(FrameRate{30, 1}), 23'520'000);
  EXPECT_EQ(frameDuration(FrameRate{60, 1}), 11'760'000);
  EXPECT_EQ(frameDuration(FrameRate{144, 1}), 4'900'000);
  EXPECT_EQ(frameDuration(FrameRate{30000, 1001}), 23'543'520);
  // 705600000 = 2^9 · 3^2 · 5^5 · 7^2: 11 and 13 fps would drift against the clock.
  EXPECT_THROW(frameDuration(FrameRate{11, 1}), std::invalid_argument);
  EXPECT_THROW(frameDuration(FrameRate{13, 1}), std::invalid_argument);
  EXPECT_THROW(frameDuration(FrameRate{0, 1}), std::invalid_argument);
  EXPECT_THROW(frameDuration(FrameRate{60, 0}), std::invalid_argument);
  EXPECT_EQ(flicksFromSeconds(0.1), 70'560'000);
  EXPECT_EQ(flicksFromSeconds(1.0 / 3.0), 235'200'000);
  EXPECT_THROW(flicksFromSeconds(-1.0), std::invalid_argument);
  EXPECT_THROW(flicksFromSeconds(std::numeric_limits<double>::quiet_NaN()), std::invalid_argument);
}

// ⌈T · rate / kFlicksPerSecond⌉: the ticks a frame at T needs to show the state at T.
std::int64_t ticksToShow(Flicks total, std::int64_t rate) {
  const __int128 units = static_cast<__int128>(total) * rate;
  return static_cast<std::int64_t>((units + kFlicksPerSecond - 1) / kFlicksPerSecond);
}

// α is the float nearest the exact fraction (rounded once): neither neighbour is closer.
::testing::AssertionResult isNearestFloat(float alpha, Flicks total, std::int64_t rate) {
  const __int128 units = static_cast<__int128>(total) * rate;
  const auto r = static_cast<long double>(static_cast<std::int64_t>(units % kFlicksPerSecond));
  const long double exact = r / kFlicksPerSecond;
  const long double miss = std::fabs(static_cast<long double>(alpha) - exact);
  for (float neighbour : {std::nextafter(alpha, 0.0f), std::nextafter(alpha, 2.0f)}) {
    if (std::fabs(static_cast<long double>(neighbour) - exact) < miss) {
      return ::testing::AssertionFailure()
             << "α " << alpha << " is not the float nearest " << static_cast<double>(exact);
    }
  }
  return ::testing::AssertionSuccess();
}

// Any frame sequence, frames shown at their own time: after frames totalling T flicks the
// driver has issued ⌈T · rate⌉ ticks (the tick at or after T), and α places T between the last
// two: the exact fraction rounded once, or 1 when T falls on a tick.
TEST(FixedStepDriver, AtFrameTimeRunsTheTickAtOrAfterTheFrame) {
  for (std::int64_t rate : {1, 7, 60, 144, 1000, 1'000'000}) {
    for (const auto& [minFrame, maxFrame] : std::vector<std::pair<Flicks, Flicks>>{
             {0, 100}, {0, kSecond / 5}, {kSecond, 3 * kSecond}}) {
      FixedStepDriver driver(rate, std::int64_t{1} << 40);
      test::JitteredFrames frames(static_cast<std::uint64_t>(rate), minFrame, maxFrame);
      Flicks total = 0;
      std::int64_t ticks = 0;
      for (int f = 0; f < 500; ++f) {
        const Flicks frame = frames.next();
        const AdvanceResult r = driver.advance(frame);
        total += frame;
        ticks += r.ticks;
        ASSERT_EQ(ticks, ticksToShow(total, rate)) << rate << " Hz, frame " << f;
        ASSERT_EQ(driver.ticksIssued(), ticks);
        ASSERT_EQ(driver.ticksDue(), ticksIn(total, rate));
        ASSERT_EQ(r.ticksDropped, 0);
        ASSERT_EQ(r.ticksPending, 0);
        if (fractionIn(total, rate) == 0.0) {
          ASSERT_EQ(r.alpha, 1.0f) << "on a tick: its own state";
          ASSERT_EQ(driver.frameOffset(), kFlicksPerSecond);
        } else {
          ASSERT_GT(r.alpha, 0.0f);
          ASSERT_TRUE(isNearestFloat(r.alpha, total, rate)) << rate << " Hz, frame " << f;
        }
      }
    }
  }
}

// One tick behind: the classic loop never runs a tick past the frame (⌊T · rate⌋ ticks) and α
// is the fraction past the newest tick, in [0, 1).
TEST(FixedStepDriver, OneTickBehindRunsTheTicksBeforeTheFrame) {
  for (std::int64_t rate : {1, 7, 60, 144, 1000, 1'000'000}) {
    FixedStepDriver driver(rate, std::int64_t{1} << 40, OverrunPolicy::DropExcess,
                           FrameTiming::OneTickBehind);
    test::JitteredFrames frames(static_cast<std::uint64_t>(rate), 0, kSecond / 5);
    Flicks total = 0;
    for (int f = 0; f < 500; ++f) {
      const Flicks frame = frames.next();
      const AdvanceResult r = driver.advance(frame);
      total += frame;
      ASSERT_EQ(driver.ticksIssued(), ticksIn(total, rate)) << rate << " Hz, frame " << f;
      ASSERT_GE(r.alpha, 0.0f);
      ASSERT_LT(r.alpha, 1.0f);
      if (r.alpha < std::nextafter(1.0f, 0.0f)) {
        ASSERT_TRUE(isNearestFloat(r.alpha, total, rate)) << rate << " Hz, frame " << f;
      }
    }
  }
}

// Regression (issue 10, item 16): α was float(remainder) / float(kFlicksPerSecond), rounded
// twice (the remainder has up to 30 bits, a float 24): for 1546 of these 4096 frames it was not
// the float nearest the fraction.
TEST(FixedStepDriver, AlphaIsTheExactFractionRoundedOnce) {
  int checked = 0;
  for (Flicks frame = kSecond - 4096; frame < kSecond; ++frame) {
    FixedStepDriver driver(1, 16);
    const AdvanceResult r = driver.advance(frame);
    ASSERT_TRUE(isNearestFloat(r.alpha, frame, 1)) << frame << " flicks";
    ++checked;
  }
  EXPECT_EQ(checked, 4096);
  FixedStepDriver driver(1, 16);
  // 705599999 / 705600000 = 1 − 1.4e-9: 1.0f is the nearest float, so α is 1.
  EXPECT_EQ(driver.advance(kSecond - 1).alpha, 1.0f);
  EXPECT_EQ(driver.frameOffset(), kSecond - 1) << "the exact offset keeps the truth";
}

TEST(FixedStepDriver, DropExcessCapsAOneSecondFrameAndKeepsTheFraction) {
  FixedStepDriver driver(60, 16, OverrunPolicy::DropExcess);
  const Flicks tick = frameDuration(FrameRate{60, 1});
  AdvanceResult r = driver.advance(tick / 2);
  EXPECT_EQ(r.ticks, 1);  // the tick that ends after the frame, to show it
  EXPECT_EQ(r.alpha, 0.5f);
  r = driver.advance(kSecond);  // the clock at 60.5 ticks: tick 61 shows it
  EXPECT_EQ(r.ticks, 16);
  EXPECT_EQ(r.ticksDropped, 44);
  EXPECT_EQ(r.ticksPending, 0);
  EXPECT_EQ(r.alpha, 0.5f);
  EXPECT_EQ(driver.ticksDroppedTotal(), 44);
  r = driver.advance(tick / 2);  // on a tick: no new tick needed
  EXPECT_EQ(r.ticks, 0);
  EXPECT_EQ(r.ticksDropped, 0);
  EXPECT_EQ(r.alpha, 1.0f);
  r = driver.advance(3 * kSecond);
  EXPECT_EQ(r.ticks, 16);
  EXPECT_EQ(r.ticksDropped, 164);
  EXPECT_EQ(driver.ticksIssued(), 33);
  EXPECT_EQ(driver.ticksDroppedTotal(), 208);
  // Issued plus dropped is the clock's whole ticks (the frame is on a tick).
  EXPECT_EQ(driver.ticksIssued() + driver.ticksDroppedTotal(), ticksIn(tick + 4 * kSecond, 60));
}

TEST(FixedStepDriver, FallBehindReportsTheDebtAndLaterFramesCatchUp) {
  FixedStepDriver driver(60, 16, OverrunPolicy::FallBehind);
  const Flicks tick = frameDuration(FrameRate{60, 1});
  AdvanceResult r = driver.advance(kSecond);
  EXPECT_EQ(r.ticks, 16);
  EXPECT_EQ(r.ticksPending, 44);
  EXPECT_EQ(r.ticksDropped, 0);
  EXPECT_EQ(r.alpha, 1.0f) << "behind: the newest state, not an extrapolation";
  const std::vector<std::pair<std::int64_t, std::int64_t>> expected{
      {16, 29}, {16, 14}, {15, 0}, {1, 0}};
  for (const auto& [ticks, pending] : expected) {
    r = driver.advance(tick);
    EXPECT_EQ(r.ticks, ticks);
    EXPECT_EQ(r.ticksPending, pending);
  }
  EXPECT_EQ(r.alpha, 1.0f);
  EXPECT_EQ(driver.ticksIssued(), ticksIn(kSecond + 4 * tick, 60));  // 64: nothing was lost
  EXPECT_EQ(driver.ticksDroppedTotal(), 0);
}

// Regression (issue 10, item 6): the debt was kept in flick·Hz units in 64 bits, and four
// 3600 s frames at 10⁶ Hz (2.5·10¹⁸ units each) overflowed it: 5 ticks ran where 6 were owed.
TEST(FixedStepDriver, FallBehindKeepsADebtPastSixtyFourBitsOfFlickUnits) {
  FixedStepDriver driver(1'000'000, 1, OverrunPolicy::FallBehind);
  const Flicks hour = 3600 * kSecond;
  std::int64_t ran = 0;
  for (int f = 0; f < 4; ++f) ran += driver.advance(hour).ticks;
  EXPECT_EQ(ran, 4);
  EXPECT_EQ(driver.ticksPending(), 4 * 3'600'000'000LL - 4);
  for (int f = 0; f < 2; ++f) ran += driver.advance(0).ticks;
  EXPECT_EQ(ran, 6) << "every frame runs the cap while ticks are owed";
  EXPECT_EQ(driver.ticksPending(), 4 * 3'600'000'000LL - 6);
  EXPECT_EQ(driver.ticksDue(), 4 * 3'600'000'000LL);
}

TEST(FixedStepDriver, RejectsInvalidArguments) {
  EXPECT_THROW(FixedStepDriver(0, 16), std::invalid_argument);
  EXPECT_THROW(FixedStepDriver(60, 0), std::invalid_argument);
  FixedStepDriver driver(60, 16);
  EXPECT_THROW(driver.advance(-1), std::invalid_argument);
  EXPECT_EQ(driver.advance(0).ticks, 0);
}

// NTSC: 1001 frames of 30000/1001 fps are 33.4 s exactly; every prefix issues the ceiling.
// restore() takes only a state some run of advance() reaches: a remainder below one second of
// flicks, and one tick issued ahead of the ticks due only when a frame between ticks needed it
// (AtFrameTime with a remainder). Checkpoints are checked through it.
TEST(FixedStepDriver, RestoreRefusesStatesNoRunReaches) {
  FixedStepDriver driver(60, 16);
  EXPECT_NO_THROW(driver.restore(5, 0, 4, 1));  // tick 5 shows a frame just after tick 4
  EXPECT_EQ(driver.ticksDue(), 4);
  EXPECT_NO_THROW(driver.restore(4, 0, 4, kFlicksPerSecond - 1));
  EXPECT_THROW(driver.restore(4, 0, 4, kFlicksPerSecond), std::invalid_argument);
  EXPECT_THROW(driver.restore(5, 0, 4, 0), std::invalid_argument) << "on a tick: none ahead";
  EXPECT_THROW(driver.restore(6, 0, 4, 1), std::invalid_argument);
  EXPECT_THROW(driver.restore(4, 0, 4, -1), std::invalid_argument);
  FixedStepDriver behind(60, 16, OverrunPolicy::DropExcess, FrameTiming::OneTickBehind);
  EXPECT_THROW(behind.restore(5, 0, 4, 1), std::invalid_argument) << "never ahead";
  EXPECT_NO_THROW(behind.restore(4, 0, 4, 1));
}

// A frame a flick before the next tick: offset/F = 1 − 1.4e-9 rounds to 1.0f. At frame time
// that is the float nearest the frame's time; one tick behind must stay below the newest tick.
TEST(FixedStepDriver, AlphaAFlickBeforeATickRoundsToOneOnlyAtFrameTime) {
  FixedStepDriver atFrame(60, 16);
  atFrame.restore(5, 0, 4, kFlicksPerSecond - 1);
  EXPECT_EQ(atFrame.frameOffset(), kFlicksPerSecond - 1);
  EXPECT_EQ(atFrame.alpha(), 1.0f);
  FixedStepDriver behind(60, 16, OverrunPolicy::DropExcess, FrameTiming::OneTickBehind);
  behind.restore(4, 0, 4, kFlicksPerSecond - 1);
  EXPECT_EQ(behind.frameOffset(), kFlicksPerSecond - 1);
  EXPECT_EQ(behind.alpha(), std::nextafter(1.0f, 0.0f));
}

// A driver restored from another's four numbers is that driver: it reads them back and the next
// frames issue the same ticks, drops and interpolation factors.
TEST(FixedStepDriver, ARestoredDriverContinuesAsTheOneItWasSavedFrom) {
  const Flicks frame = frameDuration(FrameRate{30000, 1001});
  FixedStepDriver saved(60, 3);
  saved.advance(kFlicksPerSecond / 4);  // 15 ticks due, the cap of 3 drops 12
  for (int f = 0; f < 7; ++f) saved.advance(frame);
  ASSERT_GT(saved.ticksDroppedTotal(), 0);
  ASSERT_GT(saved.remainder(), 0);
  FixedStepDriver restored(60, 3);
  restored.restore(saved.ticksIssued(), saved.ticksDroppedTotal(), saved.ticksDue(),
                   saved.remainder());
  EXPECT_EQ(restored.ticksIssued(), saved.ticksIssued());
  EXPECT_EQ(restored.ticksDroppedTotal(), saved.ticksDroppedTotal());
  EXPECT_EQ(restored.ticksDue(), saved.ticksDue());
  EXPECT_EQ(restored.remainder(), saved.remainder());
  EXPECT_EQ(restored.frameOffset(), saved.frameOffset());
  for (int f = 0; f < 20; ++f) {
    const AdvanceResult a = saved.advance(f % 3 == 0 ? 2 * frame : frame);
    const AdvanceResult b = restored.advance(f % 3 == 0 ? 2 * frame : frame);
    ASSERT_EQ(a.ticks, b.ticks) << "frame " << f;
    ASSERT_EQ(a.ticksDropped, b.ticksDropped) << "frame " << f;
    ASSERT_EQ(test::bitsOf(a.alpha), test::bitsOf(b.alpha)) << "frame " << f;
  }
  EXPECT_EQ(restored.ticksDroppedTotal(), saved.ticksDroppedTotal());
}

TEST(FixedStepDriver, NtscFrameRateAddsUpExactly) {
  const Flicks frame = frameDuration(FrameRate{30000, 1001});
  FixedStepDriver driver(60, 16);
  for (int f = 1; f <= 1001; ++f) {
    const AdvanceResult r = driver.advance(frame);
    ASSERT_EQ(driver.ticksIssued(), ticksToShow(f * frame, 60)) << "frame " << f;
    if (fractionIn(f * frame, 60) == 0.0) {
      ASSERT_EQ(r.alpha, 1.0f);
    } else {
      ASSERT_TRUE(isNearestFloat(r.alpha, f * frame, 60));
    }
  }
  EXPECT_EQ(driver.ticksIssued(), 2005);  // 1001 · 1001/30000 s · 60 Hz = 2004.002
  EXPECT_EQ(driver.ticksDue(), 2004);
}

// ---- the system under the driver -------------------------------------------------------------

struct Checkpoints {
  std::map<int, std::uint64_t> hash;  // seconds → state hash
  std::map<int, std::size_t> alive;
  std::map<int, std::uint64_t> born;
};

const std::vector<int> kCheckSeconds{1, 2, 5};

// The reference: ticks run directly, no driver.
Checkpoints stepDirectly(const SystemSettings& settings) {
  Checkpoints c;
  const auto system = test::referenceSystem(settings);
  for (int s : kCheckSeconds) {
    system->stepTicks(s * settings.stepRateHz - system->tickCount());
    c.hash[s] = stateHash(system->pool());
    c.alive[s] = system->pool().size();
    c.born[s] = system->pool().nextId();
  }
  return c;
}

// Advances by frames from `next` until each checkpoint, trimming the frame that would overshoot
// it; checks the tick count and α after every frame.
Checkpoints advanceByFrames(const SystemSettings& settings, const std::function<Flicks()>& next) {
  Checkpoints c;
  const auto system = test::referenceSystem(settings);
  Flicks elapsed = 0;
  for (int s : kCheckSeconds) {
    const Flicks target = s * kSecond;
    while (elapsed < target) {
      const Flicks frame = std::min(next(), target - elapsed);
      const AdvanceResult r = system->advance(frame);
      elapsed += frame;
      EXPECT_EQ(r.ticksDropped, 0);
      EXPECT_EQ(system->tickCount(), ticksToShow(elapsed, settings.stepRateHz));
      EXPECT_GT(system->alpha(), 0.0f);
      EXPECT_LE(system->alpha(), 1.0f);
    }
    EXPECT_EQ(system->alpha(), 1.0f);  // whole seconds are whole ticks, shown as they are
    c.hash[s] = stateHash(system->pool());
    c.alive[s] = system->pool().size();
  }
  return c;
}

class FrameIndependence : public ::testing::TestWithParam<std::string> {};

// A regression guard: every frame schedule runs the same ticks through the same code, so the
// hashes agree unless the frames leak into a tick (a float time accumulator in the driver makes
// this fail). The tick counts and α after every frame are real checks of the driver.
TEST_P(FrameIndependence, SameStateHashAtOneTwoAndFiveSecondsForAnyFramesRegressionGuard) {
  const SystemSettings settings = test::referenceSettings(GetParam());
  const Checkpoints reference = stepDirectly(settings);
  // Particles are born and die during the run: the comparison is not of an empty pool.
  EXPECT_GT(reference.alive.at(1), 100u);
  EXPECT_GT(reference.alive.at(5), 100u);
  EXPECT_GT(reference.born.at(1), reference.alive.at(1));  // and some have died by 1 s
  ASSERT_NE(reference.hash.at(1), reference.hash.at(2));

  for (std::int64_t fps : {24, 30, 60, 144}) {
    const Flicks frame = frameDuration(FrameRate{fps, 1});
    const Checkpoints c = advanceByFrames(settings, [frame] { return frame; });
    for (int s : kCheckSeconds) {
      EXPECT_EQ(c.hash.at(s), reference.hash.at(s)) << fps << " fps, " << s << " s";
    }
  }
  // Frames between 1/240 s and 1/10 s.
  test::JitteredFrames jitter(99, kSecond / 240, kSecond / 10);
  const Checkpoints c = advanceByFrames(settings, [&jitter] { return jitter.next(); });
  for (int s : kCheckSeconds) {
    EXPECT_EQ(c.hash.at(s), reference.hash.at(s)) << "jittered frames, " << s << " s";
  }
}

std::string schemeName(const ::testing::TestParamInfo<std::string>& info) { return info.param; }

INSTANTIATE_TEST_SUITE_P(AllSchemes, FrameIndependence, ::testing::ValuesIn(integratorNames()),
                         schemeName);

// A regression guard for NTSC frames (see FrameIndependence): the same tick path as stepTicks.
TEST(SystemDriver, NtscFramesReachTheSameStatesRegressionGuard) {
  const SystemSettings settings = test::referenceSettings();
  const auto reference = test::referenceSystem(settings);
  const auto system = test::referenceSystem(settings);
  const Flicks frame = frameDuration(FrameRate{30000, 1001});
  for (int f = 1; f <= 150; ++f) {
    system->advance(frame);
    ASSERT_EQ(system->tickCount(), ticksToShow(f * frame, 60));
    ASSERT_LT(system->alpha(), 1.0f);
  }
  EXPECT_EQ(system->tickCount(), 301);  // 150 frames = 5.005 s, shown between ticks 300 and 301
  EXPECT_NEAR(system->alpha(), 0.3, kAlphaTolerance);
  reference->stepTicks(301);
  EXPECT_EQ(stateHash(system->pool()), stateHash(reference->pool()));
}

TEST(SystemDriver, DropExcessRunsTheCapOnAOneSecondFrame) {
  SystemSettings settings = test::referenceSettings();
  settings.overrunPolicy = OverrunPolicy::DropExcess;
  const auto system = test::referenceSystem(settings);
  const AdvanceResult r = system->advance(kSecond);
  EXPECT_EQ(r.ticks, 16);
  EXPECT_EQ(r.ticksDropped, 44);
  EXPECT_EQ(system->tickCount(), 16);
  const auto reference = test::referenceSystem(settings);
  reference->stepTicks(16);
  EXPECT_EQ(stateHash(system->pool()), stateHash(reference->pool()));
}

// step() after a frame between ticks shows the new tick itself: α = 1, the shown time the tick's,
// and the render copies the tick's own positions, not an interpolation left over from advance().
TEST(SystemDriver, StepAfterAFrameBetweenTicksShowsTheNewTick) {
  const auto system = test::referenceSystem(test::referenceSettings());
  system->advance(kSecond / 60 * 10 + kSecond / 120);  // 10.5 ticks: shows tick 10.5
  ASSERT_EQ(system->tickCount(), 11);
  ASSERT_EQ(system->alpha(), 0.5f);
  EXPECT_DOUBLE_EQ(system->shownSeconds(), 10.5 / 60.0);
  system->step();
  EXPECT_EQ(system->tickCount(), 12);
  EXPECT_EQ(system->alpha(), 1.0f);
  EXPECT_EQ(system->shownSeconds(), 12.0 / 60.0);
  Vec3Column shown;
  system->renderPositions(shown);
  const Eigen::Index n = static_cast<Eigen::Index>(system->pool().size());
  ASSERT_GT(n, 0);
  for (int c = 0; c < 3; ++c) {
    EXPECT_TRUE((shown[c] == system->pool().position()[c].head(n)).all()) << c;
  }
}

TEST(SystemDriver, FallBehindCatchesUpOnLaterFrames) {
  SystemSettings settings = test::referenceSettings();
  settings.overrunPolicy = OverrunPolicy::FallBehind;
  const auto system = test::referenceSystem(settings);
  const AdvanceResult r = system->advance(kSecond);
  EXPECT_EQ(r.ticks, 16);
  EXPECT_EQ(r.ticksPending, 44);
  const Flicks tick = frameDuration(FrameRate{60, 1});
  for (int f = 0; f < 4; ++f) system->advance(tick);
  EXPECT_EQ(system->tickCount(), 64);
  const auto reference = test::referenceSystem(settings);
  reference->stepTicks(64);
  EXPECT_EQ(stateHash(system->pool()), stateHash(reference->pool()));
}

// R = 37.5 particles/s for 2 s is exactly 75 particles, whatever the step rate and the frames.
TEST(RateEmission, EmitsFloorOfRateTimesDurationAtAnyFramerate) {
  EmitterSettings e;
  e.rate = 37.5;
  e.speed = 1.0;  // infinite lifetime: every particle emitted is still alive
  for (std::int64_t stepRate : {60, 7, 1000}) {
    SystemSettings settings = test::referenceSettings();
    settings.stepRateHz = stepRate;
    settings.maxTicksPerFrame = 1000;  // no frame may drop ticks here
    std::vector<std::function<Flicks()>> framings;
    for (std::int64_t fps : {24, 30, 60, 144}) {
      const Flicks frame = frameDuration(FrameRate{fps, 1});
      framings.emplace_back([frame] { return frame; });
    }
    auto jitter = std::make_shared<test::JitteredFrames>(5, kSecond / 240, kSecond / 10);
    framings.emplace_back([jitter] { return jitter->next(); });
    for (std::size_t k = 0; k < framings.size(); ++k) {
      ParticleSystem system(settings, {e}, test::gravityOnly());
      Flicks elapsed = 0;
      while (elapsed < 2 * kSecond) {
        const Flicks frame = std::min(framings[k](), 2 * kSecond - elapsed);
        system.advance(frame);
        elapsed += frame;
      }
      EXPECT_EQ(system.pool().size(), 75u) << stepRate << " Hz, framing " << k;
      EXPECT_EQ(system.pool().nextId(), 75u) << stepRate << " Hz, framing " << k;
    }
  }
}

// Within a run the count follows the ticks: floor(R · k / H) after k ticks, never ahead, never a
// particle lost to rounding (37.5 / 60 = 0.625 per tick).
TEST(RateEmission, CountAfterEveryTickIsTheFloor) {
  EmitterSettings e;
  e.rate = 37.5;
  SystemSettings settings = test::referenceSettings();
  ParticleSystem system(settings, {e}, ForceSet{});
  for (std::int64_t k = 1; k <= 240; ++k) {
    system.step();
    ASSERT_EQ(system.pool().nextId(), static_cast<std::uint64_t>(k * 375 / 600)) << "tick " << k;
  }
}

}  // namespace
}  // namespace tickfx
