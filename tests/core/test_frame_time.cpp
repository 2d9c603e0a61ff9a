// Which time things happen at: times in seconds on the tick grid, emission counts, and frames
// that show the state at their own time (issue 10, items 1, 2 and 5).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <tuple>
#include <vector>

#include "CoreTestSupport.h"
#include "particles/EmissionRate.h"
#include "particles/ExactTime.h"

namespace tickfx {
namespace {

std::vector<std::int64_t> sweptRates() {
  std::vector<std::int64_t> rates;
  for (std::int64_t h = 1; h <= 2000; ++h) rates.push_back(h);
  for (std::int64_t h : {4096, 44100, 1'000'000}) rates.push_back(h);
  return rates;
}

// Regression (item 1): times went through the nearest flick before the ceiling to a tick, so at
// step rates that do not divide 705 600 000 (11, 97, 1024, 10⁶ Hz, ...) k/H could round up past
// tick k. Now k/H, however it is computed, is tick k, and the next double above it tick k + 1.
TEST(ExactTime, TimeKOverHIsTickKAtEveryStepRate) {
  for (std::int64_t h : sweptRates()) {
    for (std::int64_t k : {std::int64_t{1}, std::int64_t{2}, std::int64_t{3}, h - 1, h, h + 1,
                           7 * h + 5, 1000 * h - 1}) {
      if (k < 1) continue;
      const double t = static_cast<double>(k) / static_cast<double>(h);
      ASSERT_EQ(exact::tickAtOrAfter(t, h), k) << k << "/" << h;
      ASSERT_EQ(exact::tickAtOrAfter(std::nextafter(t, 2.0 * t), h), k + 1) << k << "/" << h;
      ASSERT_EQ(exact::tickAtOrAfter(std::nextafter(t, 0.0), h), k) << k << "/" << h;
    }
  }
  EXPECT_EQ(exact::tickAtOrAfter(0.0009765625, 1024), 1);  // the burst: was tick 2
  EXPECT_EQ(exact::tickAtOrAfter(0.1, 10), 1);
  EXPECT_EQ(exact::tickAtOrAfter(1.6, 120), 192);
  EXPECT_EQ(exact::tickAtOrAfter(0.0, 60), 0);
  EXPECT_EQ(exact::tickAtOrAfter(1e-300, 60), 1);
  EXPECT_EQ(exact::tickAtOrAfter(1e9, 1'000'000), 1'000'000'000'000'000);
  EXPECT_THROW(exact::tickAtOrAfter(-1.0, 60), std::invalid_argument);
  EXPECT_THROW(exact::tickAtOrAfter(std::numeric_limits<double>::infinity(), 60),
               std::invalid_argument);
}

// A burst and a structure at 1/1024 s at 1024 Hz are born at tick 1: after one second their age
// is 1023/1024 s (it was 1022/1024, a tick late).
// dyadic() is exact: numerator · 2^-shift gives x back, with numerator < 2^53, for normal and
// subnormal doubles, 0 and the largest accepted.
TEST(ExactTime, DyadicIsTheDoubleExactly) {
  for (const double x : {0.0, 0.75, 1.0, 0.1, 1.0 / 3.0, 1e9, 0x1p-76, 0x1.8p-76, 1e-300,
                         std::numeric_limits<double>::denorm_min(), std::nextafter(0x1p53, 0.0)}) {
    const exact::Dyadic d = exact::dyadic(x);
    EXPECT_LT(d.numerator, std::uint64_t{1} << 53) << x;
    EXPECT_GE(d.shift, 0) << x;
    EXPECT_EQ(std::ldexp(static_cast<double>(d.numerator), -d.shift), x) << x;
  }
  EXPECT_EQ(exact::dyadic(0.75).numerator, 3ull << 51);
  EXPECT_EQ(exact::dyadic(0.75).shift, 53);
  EXPECT_THROW(exact::dyadic(0x1p53), std::invalid_argument);
  EXPECT_THROW(exact::dyadic(-0.5), std::invalid_argument);
}

// Times so small that m · H must be shifted right by 127, 128 or 129 bits (2^-75, 2^-76, 2^-77):
// past the width of the integers, where a shift would be undefined, and still after tick 0.
TEST(ExactTime, TheSmallestPositiveTimesAreTickOne) {
  for (const double t : {0x1p-75, 0x1.fffffffffffffp-76, 0x1p-76, 0x1.8p-76, 0x1p-77}) {
    for (const std::int64_t h : {1, 60, 1'000'000}) {
      EXPECT_EQ(exact::tickAtOrAfter(t, h), 1) << t << " s at " << h << " Hz";
    }
  }
  EXPECT_EQ(exact::dyadic(0x1p-76).shift, 128);
}

TEST(ExactTime, BurstsAndStructuresAreBornOnTheirTick) {
  SystemSettings settings = test::referenceSettings();
  settings.stepRateHz = 1024;
  EmitterSettings burst;
  burst.bursts = {Burst{0.0009765625, 1}};
  StructureSettings rope;
  rope.time = 0.0009765625;
  ParticleSystem system(settings, {burst}, ForceSet{}, {rope});
  system.stepTicks(1);
  EXPECT_EQ(system.pool().size(), 0u);
  system.stepTicks(1023);
  ASSERT_EQ(system.pool().size(), 11u);  // the burst's particle and the rope's ten
  for (std::size_t i = 0; i < system.pool().size(); ++i) {
    EXPECT_EQ(system.pool().birthTick()[i], 1u);
    EXPECT_EQ(system.pool().age(i), 1023.0f / 1024.0f);
  }
}

// Regression (item 5): with start or stop between ticks the count followed the ticks (10 Hz,
// rate 10: stop = 0.15 made 2, stop = 0.05 made 1). A whole emission makes ⌊rate·(stop − start)⌋
// with the times as written, at every step rate.
TEST(EmissionRate, AWholeEmissionMakesRateTimesDurationAtAnyStepRate) {
  struct Case {
    double rate, start, stop;
    std::uint64_t made;
  };
  const std::vector<Case> cases = {
      {10, 0.0, 0.15, 1},   {10, 0.0, 0.05, 0},   {10, 0.0, 0.3, 3},    {10, 0.05, 0.35, 3},
      {10, 0.1, 0.7, 6},    {37.5, 0.0, 2.0, 75}, {3, 1.0 / 3, 1.0, 2}, {1e6, 0.0, 1e-6, 1},
      {7, 0.123, 0.123, 0}, {0.5, 0.0, 1.999, 0}, {0.5, 0.25, 2.25, 1}, {2000, 0.0, 2.0, 4000}};
  for (const Case& c : cases) {
    for (std::int64_t h : {1, 7, 10, 60, 97, 120, 1000, 1024, 44100}) {
      const EmissionRate rate(std::llround(c.rate * 1e6), c.start, c.stop, h);
      const auto lastTick = static_cast<std::int64_t>(std::ceil(c.stop * static_cast<double>(h)));
      EXPECT_EQ(rate.madeThrough(lastTick + 2), c.made)
          << c.rate << "/s over [" << c.start << ", " << c.stop << ") at " << h << " Hz";
      std::uint64_t previous = 0;
      for (std::int64_t k = -1; k <= lastTick + 2; ++k) {
        const std::uint64_t made = rate.madeThrough(k);
        ASSERT_GE(made, previous) << "never fewer later";
        previous = made;
      }
    }
  }
}

// Within the emission, by the end of tick k: ⌊rate·((k+1)/H − start)⌋, the particles accrued.
TEST(EmissionRate, EachTickMakesThoseThatAccrueInIt) {
  const EmissionRate rate(10'000'000, 0.05, 1.0, 10);  // 10 a second from 0.05 s, 10 Hz
  const std::vector<std::uint64_t> expected = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 9, 9};
  for (std::int64_t k = 0; k < static_cast<std::int64_t>(expected.size()); ++k) {
    // By (k+1)/10 s: ⌊10·((k+1)/10 − 0.05)⌋ = k; the last, at 1.0 s, makes ⌊10·0.95⌋ = 9.
    EXPECT_EQ(rate.madeThrough(k), expected[static_cast<std::size_t>(k)]) << "tick " << k;
  }
  EXPECT_EQ(rate.madeThrough(-1), 0u);
}

// Regression (item 16): emit() sampled every particle of a tick, including those the full pool
// would refuse. A burst of 10¹² into a pool of ten took hours; now the refused are counted.
TEST(EmissionRate, SpawnsThePoolRefusesAreCountedNotSampled) {
  SystemSettings settings = test::referenceSettings();
  settings.maxParticles = 10;
  EmitterSettings e;
  e.bursts = {Burst{0.0, 1'000'000'000'000}};
  ParticleSystem system(settings, {e}, ForceSet{});
  system.step();
  EXPECT_EQ(system.pool().size(), 10u);
  EXPECT_EQ(system.pool().nextId(), 10u);
  EXPECT_EQ(system.pool().droppedSpawns(), 1'000'000'000'000u - 10u);
}

// ---- frames at their own time (item 2) -------------------------------------------------------

struct Shown {
  Vec3Column position, velocity;
  FloatColumn age;
  static Shown of(const ParticleSystem& s) {
    Shown v;
    s.renderPositions(v.position);
    s.renderVelocities(v.velocity);
    s.renderAges(v.age);
    return v;
  }
};

// One particle at 1 m/s along x under gravity, 120 Hz, semi-implicit Euler: its velocity after k
// ticks is exactly −g·k·dt in y, and x = t. Frames at 50 fps fall between ticks; at 24 fps on
// them. Regression: frame 1 at 50 fps showed x = 0.01167 m (tick 1.4) where the particle is at
// 0.02 m, and at 24 fps x = 1/30 m (tick 4) beside an age of 1/24 s (tick 5).
TEST(FrameTime, AFrameShowsTheStateAtItsOwnTime) {
  for (std::int64_t fps : {50, 24, 144, 7}) {
    SystemSettings settings = test::referenceSettings();
    settings.stepRateHz = 120;
    settings.maxTicksPerFrame = 1000;  // 7 fps needs 18 ticks a frame
    EmitterSettings e;
    e.bursts = {Burst{0.0, 1}};
    e.direction = Eigen::Vector3d::UnitX();
    e.speed = 1.0;
    ParticleSystem system(settings, {e}, test::gravityOnly());
    const Flicks frame = frameDuration(FrameRate{fps, 1});
    for (int f = 1; f <= 2 * static_cast<int>(fps); ++f) {
      system.advance(frame);
      const double t = static_cast<double>(f) / static_cast<double>(fps);
      const Shown shown = Shown::of(system);
      ASSERT_EQ(shown.position.x.size(), 1);
      EXPECT_NEAR(shown.position.x[0], t, 4e-6 * (1 + t)) << fps << " fps, frame " << f;
      EXPECT_NEAR(shown.age[0], t, 1e-6 * (1 + t)) << fps << " fps, frame " << f;
      EXPECT_NEAR(shown.velocity.y[0], -9.81 * t, 2e-5 * (1 + t)) << fps << " fps, frame " << f;
      EXPECT_NEAR(system.shownSeconds(), t, 1e-12);
    }
  }
}

// On a tick a frame is the tick's own state, bit for bit; between ticks it lies between them.
TEST(FrameTime, OnATickTheFrameIsTheTicksOwnState) {
  SystemSettings settings = test::referenceSettings();
  const auto system = test::referenceSystem(settings);  // 60 Hz, emitting, gravity and wind
  const Flicks frame = frameDuration(FrameRate{24, 1});
  for (int f = 1; f <= 48; ++f) {
    system->advance(frame);
    const Shown shown = Shown::of(*system);
    const ParticlePool& pool = system->pool();
    const auto n = static_cast<Eigen::Index>(pool.size());
    ASSERT_GT(n, 0);
    if (f % 2 == 0) {  // every other 24 fps frame falls on a 60 Hz tick
      EXPECT_EQ(system->alpha(), 1.0f);
      for (int c = 0; c < 3; ++c) {
        EXPECT_TRUE((shown.position[c] == pool.position()[c].head(n)).all()) << "frame " << f;
        EXPECT_TRUE((shown.velocity[c] == pool.velocity()[c].head(n)).all()) << "frame " << f;
      }
      EXPECT_TRUE((shown.age == test::agesOf(pool)).all()) << "frame " << f;
    } else {
      EXPECT_EQ(system->alpha(), 0.5f);
      EXPECT_TRUE((shown.age < test::agesOf(pool)).all()) << "half a tick younger";
      EXPECT_TRUE((shown.age >= 0.0f).all());
    }
  }
}

// Between ticks a shown position is exactly what ParticleSystem::interpolatedPositions()
// documents: previous + (current − previous) · α, in float, for every row, with α the driver's
// fraction computed from integers (60 Hz ticks, 50 fps frames: α = 0.2, 0.4, 0.6, 0.8, then a
// tick). Velocities interpolate the same way between the tick's start and end velocities.
TEST(FrameTime, BetweenTicksAShownValueIsPreviousPlusAlphaTimesTheStep) {
  SystemSettings settings = test::referenceSettings();
  const auto system = test::referenceSystem(settings);  // 60 Hz, emitting, gravity and wind
  const Flicks frame = frameDuration(FrameRate{50, 1});
  int between = 0;
  for (int f = 1; f <= 50; ++f) {
    system->advance(frame);
    const float alpha = system->alpha();
    const float expectedAlpha = static_cast<float>((f * 6) % 5) / 5.0f;
    if (f % 5 == 0) {
      ASSERT_EQ(alpha, 1.0f) << "frame " << f;
      continue;
    }
    ASSERT_EQ(alpha, expectedAlpha) << "frame " << f;
    ++between;
    const Shown shown = Shown::of(*system);
    const ParticlePool& pool = system->pool();
    const Vec3Column* start = system->tickStartVelocities();
    ASSERT_NE(start, nullptr) << "advance() keeps the velocities a frame between ticks needs";
    for (int c = 0; c < 3; ++c) {
      for (Eigen::Index i = 0; i < static_cast<Eigen::Index>(pool.size()); ++i) {
        const float p = pool.previousPosition()[c][i], q = pool.position()[c][i];
        ASSERT_EQ(shown.position[c][i], p + (q - p) * alpha) << "frame " << f << ", row " << i;
        const float u = (*start)[c][i], v = pool.velocity()[c][i];
        ASSERT_EQ(shown.velocity[c][i], u + (v - u) * alpha) << "frame " << f << ", row " << i;
      }
    }
  }
  EXPECT_EQ(between, 40);
}

// Between ticks k and k + 1 a frame shows the particles alive after tick k + 1: one born in that
// tick from its birth state (age = the time since its birth), one that dies in it not at all.
TEST(FrameTime, BirthsAndDeathsBetweenTwoTicks) {
  SystemSettings settings = test::referenceSettings();
  settings.stepRateHz = 10;
  EmitterSettings born;  // born at tick 5 (0.5 s), moving at 2 m/s along x
  born.bursts = {Burst{0.5, 1}};
  born.direction = Eigen::Vector3d::UnitX();
  born.speed = 2.0;
  EmitterSettings dying;  // born at 0, dies when its age reaches 0.6 s, at the end of tick 5
  dying.bursts = {Burst{0.0, 1}};
  dying.lifetime = 0.6;
  ParticleSystem system(settings, {born, dying}, ForceSet{});
  // 0.55 s: between tick 5 (0.5 s) and tick 6 (0.6 s), α = 1/2.
  system.advance(frameDuration(FrameRate{20, 1}) * 11);
  EXPECT_EQ(system.tickCount(), 6);
  EXPECT_EQ(system.alpha(), 0.5f);
  ASSERT_EQ(system.pool().size(), 1u) << "the dying particle is gone after tick 6";
  const Shown shown = Shown::of(system);
  EXPECT_EQ(system.pool().id()[0], 1u);
  EXPECT_NEAR(shown.age[0], 0.05f, 1e-7f);
  EXPECT_NEAR(shown.position.x[0], 0.1f, 1e-7f);  // 2 m/s · 0.05 s from its birth point
  EXPECT_EQ(shown.velocity.x[0], 2.0f);
}

// Interpolated ages are computed from integers: the same bits for the same frame time however
// the frames got there, like the state. A regression guard: both schedules render a shared frame
// from the same two ticks through the same code, so this fails only if the frame history leaks
// into what a frame shows (a float α or age accumulated frame by frame would).
TEST(FrameTime, SharedFramesAreBitwiseEqualAcrossFrameRatesRegressionGuard) {
  const SystemSettings settings = test::referenceSettings();
  const auto a = test::referenceSystem(settings);
  const auto b = test::referenceSystem(settings);
  const Flicks fa = frameDuration(FrameRate{25, 1}), fb = frameDuration(FrameRate{50, 1});
  for (int f = 1; f <= 25; ++f) {
    a->advance(fa);
    b->advance(fb);
    b->advance(fb);
    const Shown sa = Shown::of(*a), sb = Shown::of(*b);
    ASSERT_EQ(sa.age.size(), sb.age.size());
    for (int c = 0; c < 3; ++c) {
      EXPECT_TRUE((sa.position[c] == sb.position[c]).all()) << "frame " << f;
      EXPECT_TRUE((sa.velocity[c] == sb.velocity[c]).all()) << "frame " << f;
    }
    EXPECT_TRUE((sa.age == sb.age).all()) << "frame " << f;
  }
}

}  // namespace
}  // namespace tickfx
