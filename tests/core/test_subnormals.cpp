// No subnormal state: every value an integrator stores is flushed to a zero of its sign when it
// is subnormal (flushTiny, integrators/CheckedRows.h), so a long decay reaches exact zeros, on
// every platform alike, instead of ticking on subnormals at a fraction of the speed.
#include <gtest/gtest.h>

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

// What flushTiny must give: a subnormal's zero of the same sign; anything else unchanged.
std::uint32_t expectedBits(std::uint32_t bits) {
  const bool subnormal = (bits & 0x7f800000U) == 0 && (bits & 0x007fffffU) != 0;
  return subnormal ? (bits & 0x80000000U) : bits;
}

TEST(FlushTiny, SubnormalsBecomeSignedZerosAndNothingElseChanges) {
  const std::vector<std::uint32_t> cases{
      0x00000000U, 0x80000000U,               // ±0 stay
      0x00000001U, 0x80000001U,               // the smallest subnormals
      0x007fffffU, 0x807fffffU,               // the largest subnormals
      0x00400000U, 0x80123456U,               // subnormals between
      0x00800000U, 0x80800000U,               // ±FLT_MIN stay
      0x00800001U, 0x3f800000U, 0xbf800000U,  // normals
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
  // Every exponent-zero pattern in a sweep, and its neighbours above.
  for (std::uint32_t m = 0; m < 0x00800000U; m += 0x1357U) {
    for (std::uint32_t b : {m, m | 0x80000000U, m + 0x00800000U}) {
      ASSERT_EQ(bitsOf(flushTiny(withBits(b))), expectedBits(b)) << std::hex << b;
    }
  }
}

// Particles with the velocities `speeds` (scaled per axis) at the origin, under a strong drag
// alone, stepped by the scheme `name`: every stored value of every tick is normal or zero, and
// each speed goes from a normal value straight to exact zeros.
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
    scheme->step(pool, forces, StepTime{k, kRate});
    pool.markAllStepped();
    for (std::size_t i = 0; i < pool.size(); ++i) {
      const auto r = static_cast<Eigen::Index>(i);
      for (int c = 0; c < 3; ++c) {
        for (float value : {pool.position()[c][r], pool.velocity()[c][r]}) {
          ASSERT_TRUE(value == 0.0f || std::fabs(value) >= FLT_MIN)
              << name << ", tick " << k + 1 << ", row " << i << ": " << value;
        }
      }
      const float v = pool.velocity().x[r];
      // A crossing: a normal speed within a few of FLT_MIN, then exactly zero.
      if (v == 0.0f && last[i] != 0.0f && std::fabs(last[i]) < 64.0f * FLT_MIN) crossed[i] = true;
      last[i] = v;
    }
  }
  for (std::size_t i = 0; i < pool.size(); ++i) {
    // Position Verlet's velocity is a difference of positions: where a position is far above
    // its steps (5e-32 m, steps of 1e-39), it moves by whole ulps and never settles to zero.
    const auto r = static_cast<Eigen::Index>(i);
    if (name == "position_verlet" && pool.position().x[r] != 0.0f) continue;
    EXPECT_TRUE(crossed[i]) << name << ", row " << i;
    for (int c = 0; c < 3; ++c) EXPECT_EQ(pool.velocity()[c][r], 0.0f) << name << ", row " << i;
  }
}

// Without the flush these velocities and positions would be subnormal for tens of ticks. Every
// scheme, with the position Verlet history kept, on every path of the update loops
// (particles/Isa.h), with rows in a loop's vector body (the first 16) and in its tail.
TEST(Subnormals, ADecayGoesFromNormalValuesToExactZerosInEveryScheme) {
  std::vector<float> speeds;
  for (int copy = 0; copy < 4; ++copy) {
    for (const float s : {1e-30f, 3e-35f, 1e-36f, -2.5e-37f, 1.2e-38f}) speeds.push_back(s);
  }
  for (const Isa isa : test::isasHere()) {
    const ForcedIsa forced(isa);
    SCOPED_TRACE(isaName(isa));
    for (const std::string& name : kSchemes) expectDecayToExactZeros(name, speeds);
  }
}

}  // namespace
}  // namespace tickfx
