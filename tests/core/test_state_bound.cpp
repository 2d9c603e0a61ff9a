// Integrator::boundTick (integrators/StateBound.h): the bounds a fused frame proves itself finite
// by must hold for every row within the bounds it starts from, and be near what a tick can reach.
#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "CoreTestSupport.h"
#include "fields/AnchorSpring.h"
#include "fields/LinearDrag.h"
#include "integrators/Integrator.h"
#include "integrators/StateBound.h"

namespace tickfx {
namespace {

constexpr std::int64_t kRate = 60;

// Gravity, a periodic wind and a strong drag toward a moving air: the one pass's forms.
ForceSet formForces(float k) {
  ForceSet forces = test::gravityAndWind();
  forces.add(std::make_unique<LinearDrag>(k, Eigen::Vector3f(3.0f, -2.0f, 1.0f)));
  return forces;
}

bool boundsItsTick(const std::string& name) {
  return name != "position_verlet" && name != "velocity_verlet";
}

// Rows at the corners of the bounds and inside them, every sign on every axis: the largest
// magnitude a tick can make comes from a corner (each value is a sum of the inputs' multiples).
ParticlePool cornerRows(float p, float v) {
  const std::vector<float> ps = {-p, -p / 3.0f, 0.0f, p / 2.0f, p};
  const std::vector<float> vs = {-v, -v / 5.0f, 0.0f, v / 4.0f, v};
  ParticlePool pool(ps.size() * ps.size() * vs.size() * vs.size());
  for (float px : ps) {
    for (float py : ps) {
      for (float vx : vs) {
        for (float vz : vs) {
          ParticleInit init;
          init.position = Eigen::Vector3f(px, py, -px);
          init.velocity = Eigen::Vector3f(vx, -vz, vz);
          pool.spawn(init, 0);
        }
      }
    }
  }
  pool.markAllStepped();
  return pool;
}

StateBound largestOf(const ParticlePool& pool) {
  StateBound out;
  for (int c = 0; c < 3; ++c) {
    for (std::size_t i = 0; i < pool.size(); ++i) {
      const auto r = static_cast<Eigen::Index>(i);
      out.position = std::max(out.position, static_cast<double>(std::fabs(pool.position()[c][r])));
      out.velocity = std::max(out.velocity, static_cast<double>(std::fabs(pool.velocity()[c][r])));
    }
  }
  return out;
}

// Every scheme that bounds its tick bounds what the tick makes from rows within the bounds, over
// several ticks, within a factor of it (a bound of +∞ would be sound and prove nothing).
TEST(StateBound, EveryValueATickMakesIsWithinItsBound) {
  for (const float k : {0.0f, 0.5f, 40.0f, 600.0f}) {  // 600: k·dt = 10, unstable
    for (const std::string& name : integratorNames()) {
      SCOPED_TRACE(name + ", drag " + std::to_string(k));
      const ForceSet forces = formForces(k);
      std::unique_ptr<Integrator> scheme = makeIntegrator(name);
      ParticlePool pool = cornerRows(7.0f, 11.0f);
      StateBound bound{7.0, 11.0};
      for (std::int64_t tick = 3; tick < 8; ++tick) {
        const StateBound before = bound;
        const bool bounded = scheme->boundTick(pool, forces, StepTime{tick, kRate}, bound);
        ASSERT_EQ(bounded, boundsItsTick(name));
        if (!bounded) {
          EXPECT_EQ(bound.position, before.position);  // untouched
          break;
        }
        scheme->step(pool, forces, StepTime{tick, kRate});
        pool.markAllStepped();
        const StateBound seen = largestOf(pool);
        EXPECT_LE(seen.position, bound.position) << "tick " << tick;
        EXPECT_LE(seen.velocity, bound.velocity) << "tick " << tick;
        EXPECT_GE(bound.position, before.position);
        EXPECT_GE(bound.velocity, before.velocity);
        // Near, from the rows' own start: a magnitude bound loses the signs' cancellations (a
        // drag's −k·v), not more. (Later ticks start from the bound, not from the rows.)
        if (tick == 3) {
          EXPECT_LT(bound.position, 2.0 * seen.position);
          EXPECT_LT(bound.velocity, 4.0 * seen.velocity + 1.0);
        }
      }
    }
  }
}

// What the one pass's forms do not cover (a spring reads the position) is not bounded, and a
// bound near the float limit proves nothing: the product a tick would make could overflow.
TEST(StateBound, NoProofBeyondTheFormsOrNearTheFloatLimit) {
  ParticlePool pool = cornerRows(1.0f, 1.0f);
  ForceSet spring;
  spring.add(std::make_unique<AnchorSpring>(Eigen::Vector3f(0.0f, 2.0f, 0.0f), 5.0f, 0.0f));
  const ForceSet forces = formForces(0.5f);
  for (const char* name : {"explicit_euler", "semi_implicit_euler", "midpoint", "rk4"}) {
    SCOPED_TRACE(name);
    std::unique_ptr<Integrator> scheme = makeIntegrator(name);
    StateBound bound{1.0, 1.0};
    EXPECT_FALSE(scheme->boundTick(pool, spring, StepTime{0, kRate}, bound));

    bound = StateBound{1.0e30, 1.0e30};
    ASSERT_TRUE(scheme->boundTick(pool, forces, StepTime{0, kRate}, bound));
    EXPECT_TRUE(bound.provesFinite());
    bound = StateBound{3.0e38, 1.0};  // p + v·dt rounds to at most FLT_MAX: the bound cannot say
    ASSERT_TRUE(scheme->boundTick(pool, forces, StepTime{0, kRate}, bound));
    EXPECT_FALSE(bound.provesFinite());
    EXPECT_EQ(bound.position, INFINITY);
    bound = StateBound{1.0, 0x1p126};  // k·v is past the limit
    ASSERT_TRUE(scheme->boundTick(pool, forces, StepTime{0, kRate}, bound));
    EXPECT_FALSE(bound.provesFinite());
  }
}

// The magnitudes a fused frame measures: the largest of any order of rows, infinite for an
// infinity or a NaN.
TEST(StateBound, MagnitudeBitsAreTheLargestMagnitude) {
  std::vector<float> values = {0.5f, -3.0f, 2.0f, -0.0f, 1.0e-30f, -2.75f};
  EXPECT_EQ(boundOfBits(magnitudeBits(values.data(), 0, values.size())), 3.0);
  EXPECT_EQ(boundOfBits(magnitudeBits(values.data(), 2, 4)), 2.0);
  EXPECT_EQ(boundOfBits(magnitudeBits(values.data(), 3, 4)), 0.0);
  EXPECT_EQ(boundOfBits(magnitudeBits(values.data(), 2, 2)), 0.0);
  // Exponents 128 and 127: their OR would be an infinity; their max is 2.
  values = {1.0f, 2.0f, -1.5f, FLT_MAX};
  EXPECT_EQ(boundOfBits(magnitudeBits(values.data(), 0, 3)), 2.0);
  EXPECT_EQ(boundOfBits(magnitudeBits(values.data(), 0, 4)), static_cast<double>(FLT_MAX));
  for (const float bad : {INFINITY, -INFINITY, NAN, -NAN}) {
    values = {1.0f, bad, 2.0f};
    EXPECT_EQ(boundOfBits(magnitudeBits(values.data(), 0, 3)), INFINITY);
  }
}

}  // namespace
}  // namespace tickfx
