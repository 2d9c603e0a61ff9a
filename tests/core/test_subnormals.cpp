// No subnormal state, and none on the way: every value an integrator stores is flushed to a zero
// of its sign when its magnitude is below 2⁻⁶⁴ (flushTiny, integrators/CheckedRows.h), so a long
// decay reaches exact zeros, on every platform alike, without a tick computing subnormals from its
// state (which x86 and many ARM cores do at a fraction of the speed).
#include <gtest/gtest.h>

#include <cfenv>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "CoreTestSupport.h"
#include "ForcedIsa.h"
#include "fields/LinearDrag.h"
#include "integrators/CheckedRows.h"

namespace tickfx {
namespace {

using test::bitsOf;
using test::withBits;

const std::vector<std::string> kSchemes{"explicit_euler",  "semi_implicit_euler", "midpoint",
                                        "position_verlet", "velocity_verlet",     "rk4"};

// What flushTiny must give: a zero of the same sign below 2⁻⁶⁴ in magnitude; anything else
// unchanged.
std::uint32_t expectedBits(std::uint32_t bits) {
  const std::uint32_t magnitude = bits & 0x7fffffffU;
  return magnitude < 0x1f800000U ? (bits & 0x80000000U) : bits;
}

TEST(FlushTiny, MagnitudesBelowTwoToTheMinus64BecomeSignedZerosAndNothingElseChanges) {
  EXPECT_EQ(bitsOf(kSmallestStored), 0x1f800000U);
  EXPECT_EQ(kSmallestStored, std::ldexp(1.0f, -64));
  const std::vector<std::uint32_t> cases{
      0x00000000U, 0x80000000U,               // ±0 stay
      0x00000001U, 0x80000001U,               // the smallest subnormals
      0x007fffffU, 0x807fffffU,               // the largest subnormals
      0x00800000U, 0x80800000U,               // ±FLT_MIN: below 2⁻⁶⁴, zeros too
      0x1f7fffffU, 0x9f7fffffU,               // the largest below 2⁻⁶⁴
      0x1f800000U, 0x9f800000U,               // ±2⁻⁶⁴ stay
      0x1f800001U, 0x3f800000U, 0xbf800000U,  // larger
      0x7f7fffffU, 0x7f800000U, 0xff800000U,  // FLT_MAX, ±∞
      0x7fc00000U, 0xffc00001U, 0x7f800001U,  // NaNs, signalling included
  };
  for (std::uint32_t b : cases) {
    EXPECT_EQ(bitsOf(flushTiny(withBits(b))), expectedBits(b)) << std::hex << b;
  }
  // Four lanes at a time give each lane the scalar's bits, whatever its neighbours.
  for (std::size_t i = 0; i + 4 <= cases.size(); ++i) {
    const Lanes4 in{withBits(cases[i]), withBits(cases[i + 1]), withBits(cases[i + 2]),
                    withBits(cases[i + 3])};
    const Lanes4 out = flushTiny(in);
    for (int k = 0; k < 4; ++k) {
      EXPECT_EQ(bitsOf(out[k]), expectedBits(cases[i + static_cast<std::size_t>(k)]))
          << std::hex << cases[i + static_cast<std::size_t>(k)];
    }
  }
  // A sweep of every exponent below 2⁻⁶⁴'s and a little above, each sign.
  for (std::uint32_t m = 0; m < 0x20800000U; m += 0x1357U) {
    for (std::uint32_t b : {m, m | 0x80000000U}) {
      ASSERT_EQ(bitsOf(flushTiny(withBits(b))), expectedBits(b)) << std::hex << b;
    }
  }
}

// Particles with the velocities `speeds` (scaled per axis) at the origin, under a strong drag
// alone, stepped by the scheme `name`: every stored value of every tick is zero or at least 2⁻⁶⁴
// in magnitude, each speed goes from at least 2⁻⁶⁴ straight to exact zeros, and no tick raises
// the underflow flag (no result of the ticks was subnormal, or tiny and rounded).
void expectDecayToExactZeros(const std::string& name, const std::vector<float>& speeds) {
  constexpr std::int64_t kRate = 60;
  constexpr int kTicks = 400;
  ParticlePool pool(speeds.size());
  for (float s : speeds) {
    ParticleInit init;
    init.velocity = Eigen::Vector3f(s, -0.5f * s, 0.25f * s);
    pool.spawn(init, 0);
  }
  ForceSet forces;
  forces.add(std::make_unique<LinearDrag>(20.0f));
  std::unique_ptr<Integrator> scheme = makeIntegrator(name);
  std::vector<float> last = speeds;
  std::vector<bool> crossed(speeds.size(), false);
  for (std::int64_t k = 0; k < kTicks; ++k) {
    // (So few rows are one tile, stepped on this thread, whose flags these are.)
    std::feclearexcept(FE_ALL_EXCEPT);
    scheme->step(pool, forces, StepTime{k, kRate});
    ASSERT_FALSE(std::fetestexcept(FE_UNDERFLOW)) << name << ", tick " << k + 1;
    pool.markAllStepped();
    for (std::size_t i = 0; i < pool.size(); ++i) {
      const auto r = static_cast<Eigen::Index>(i);
      for (int c = 0; c < 3; ++c) {
        for (float value : {pool.position()[c][r], pool.velocity()[c][r]}) {
          ASSERT_TRUE(value == 0.0f || std::fabs(value) >= kSmallestStored)
              << name << ", tick " << k + 1 << ", row " << i << ": " << value;
        }
      }
      const float v = pool.velocity().x[r];
      // A crossing: a speed within a few of 2⁻⁶⁴, then exactly zero.
      if (v == 0.0f && last[i] != 0.0f && std::fabs(last[i]) < 64.0f * kSmallestStored) {
        crossed[i] = true;
      }
      last[i] = v;
    }
  }
  for (std::size_t i = 0; i < pool.size(); ++i) {
    // Position Verlet's velocity is a difference of positions: where a position is far above
    // its steps, it moves by whole ulps and never settles to zero.
    const auto r = static_cast<Eigen::Index>(i);
    if (name == "position_verlet" && pool.position().x[r] != 0.0f) continue;
    EXPECT_TRUE(crossed[i]) << name << ", row " << i;
    for (int c = 0; c < 3; ++c) EXPECT_EQ(pool.velocity()[c][r], 0.0f) << name << ", row " << i;
  }
}

// Without the flush these velocities would reach the subnormal range after a hundred ticks or
// more, and stay there for tens; the positions of the slowest start below 2⁻⁶⁴. Every scheme, with
// the position Verlet history kept, on every path of the update loops (particles/Isa.h), with
// rows in a loop's vector body (the first 16) and in its tail.
TEST(Subnormals, ADecayGoesToExactZerosWithNoUnderflowInEveryScheme) {
  std::vector<float> speeds;
  for (int copy = 0; copy < 4; ++copy) {
    for (const float s : {1e-10f, 3e-15f, 1e-17f, -2.5e-19f, 6e-20f}) speeds.push_back(s);
  }
  for (const Isa isa : test::isasHere()) {
    const ForcedIsa forced(isa);
    SCOPED_TRACE(isaName(isa));
    for (const std::string& name : kSchemes) expectDecayToExactZeros(name, speeds);
  }
}

// What the test above would see without the rule, so that it can fail: the product a drag decay
// forms from a velocity just above FLT_MIN is subnormal, and raises the underflow flag.
TEST(Subnormals, TheUnderflowFlagSeesASubnormalProduct) {
  volatile float v = 2.0f * FLT_MIN, dt = 1.0f / 60.0f;
  std::feclearexcept(FE_ALL_EXCEPT);
  volatile float product = v * dt;
  EXPECT_TRUE(std::fetestexcept(FE_UNDERFLOW));
  EXPECT_LT(std::fabs(product), FLT_MIN);
}

}  // namespace
}  // namespace tickfx
