// Integrator::boundTick (particles/StateBound.h): the bounds a fused frame proves itself finite
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
#include "particles/StateBound.h"

namespace tickfx {
namespace {

constexpr std::int64_t kRate = 60;

// Gravity, a periodic wind and a strong drag toward a moving air: the one pass's forms.
ForceSet formForces(float k) {
  ForceSet forces = test::gravityAndWind();
  forces.add(std::make_unique<LinearDrag>(k, Eigen::Vector3f(3.0f, -2.0f, 1.0f)));
  return forces;
}

// Rows at the corners of the bounds and inside them, every sign on every axis: the largest
// magnitude a tick can make comes from a corner (each value is a sum of the inputs' multiples).
// The third column, where `scheme` has one (StateBound::extra), within `extra` with the signs
// that add up most: position Verlet's previous position against the position, velocity Verlet's
// acceleration with the velocity. Not `stepped`: spawned for the next tick, the third column for
// the scheme to start.
ParticlePool cornerRows(Integrator& scheme, const ForceSet& forces, float p, float v, float extra,
                        bool stepped = true) {
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
  scheme.prepare(pool, forces);
  if (!stepped) return pool;
  pool.markAllStepped();
  if (const Vec3Column* third = extraColumnOf(pool, scheme.readsPreviousPosition())) {
    Vec3Column& column = const_cast<Vec3Column&>(*third);
    const Vec3Column& along = scheme.readsPreviousPosition() ? pool.position() : pool.velocity();
    const float sign = scheme.readsPreviousPosition() ? -1.0f : 1.0f;
    for (int c = 0; c < 3; ++c) {
      for (Eigen::Index r = 0; r < static_cast<Eigen::Index>(pool.size()); ++r) {
        column[c][r] = along[c][r] == 0.0f ? (r % 2 == 0 ? extra : -extra)
                                           : std::copysign(extra, sign * along[c][r]);
      }
    }
  }
  return pool;
}

StateBound largestOf(const ParticlePool& pool, const Vec3Column* extra) {
  StateBound out;
  const auto widen = [](double& bound, float value) {
    bound = std::max(bound, static_cast<double>(std::fabs(value)));
  };
  for (int c = 0; c < 3; ++c) {
    for (std::size_t i = 0; i < pool.size(); ++i) {
      const auto r = static_cast<Eigen::Index>(i);
      widen(out.position, pool.position()[c][r]);
      widen(out.velocity, pool.velocity()[c][r]);
      if (extra != nullptr) widen(out.extra, (*extra)[c][r]);
    }
  }
  return out;
}

// Every scheme bounds what its tick makes from rows within the bounds, over several ticks, and
// within a factor of it (a bound of +∞ would be sound and prove nothing).
TEST(StateBound, EveryValueATickMakesIsWithinItsBound) {
  for (const float k : {0.0f, 0.5f, 40.0f, 600.0f}) {  // 600: k·dt = 10, unstable
    for (const std::string& name : integratorNames()) {
      SCOPED_TRACE(name + ", drag " + std::to_string(k));
      const ForceSet forces = formForces(k);
      std::unique_ptr<Integrator> scheme = makeIntegrator(name);
      ParticlePool pool = cornerRows(*scheme, forces, 7.0f, 11.0f, 5.0f);
      const Vec3Column* extra = extraColumnOf(pool, scheme->readsPreviousPosition());
      StateBound bound{7.0, 11.0, extra != nullptr ? 5.0 : 0.0};
      for (std::int64_t tick = 3; tick < 8; ++tick) {
        const StateBound before = bound;
        ASSERT_TRUE(scheme->boundTick(pool, forces, StepTime{tick, kRate}, bound));
        scheme->step(pool, forces, StepTime{tick, kRate});
        pool.markAllStepped();
        const StateBound seen = largestOf(pool, extra);
        EXPECT_LE(seen.position, bound.position) << "tick " << tick;
        EXPECT_LE(seen.velocity, bound.velocity) << "tick " << tick;
        EXPECT_LE(seen.extra, bound.extra) << "tick " << tick;
        EXPECT_GE(bound.position, before.position);
        EXPECT_GE(bound.velocity, before.velocity);
        EXPECT_GE(bound.extra, before.extra);
        // Near, from the rows' own start: a magnitude bound loses the signs' cancellations (a
        // drag's −k·v), not more. (Later ticks start from the bound, not from the rows.)
        if (tick == 3) {
          EXPECT_LT(bound.position, 2.0 * seen.position);
          EXPECT_LT(bound.velocity, 4.0 * seen.velocity + 1.0);
          EXPECT_LT(bound.extra, 4.0 * seen.extra + 1.0);
        }
      }
    }
  }
}

// Rows spawned for a tick start the third column from their position and velocity (position
// Verlet's history, velocity Verlet's first acceleration): boundSpawned() bounds what they start
// with, and the tick from there.
TEST(StateBound, ASpawnedRowsThirdColumnIsWithinItsBound) {
  for (const float k : {0.5f, 600.0f}) {
    for (const char* name : {"position_verlet", "velocity_verlet"}) {
      SCOPED_TRACE(std::string(name) + ", drag " + std::to_string(k));
      const ForceSet forces = formForces(k);
      std::unique_ptr<Integrator> scheme = makeIntegrator(name);
      ParticlePool pool = cornerRows(*scheme, forces, 7.0f, 11.0f, 0.0f, false);
      StateBound bound{7.0, 11.0, 0.0};
      ASSERT_TRUE(scheme->boundSpawned(pool, forces, StepTime{3, kRate}, bound));
      EXPECT_GT(bound.extra, 0.0);
      const StateBound started = bound;
      ASSERT_TRUE(scheme->boundTick(pool, forces, StepTime{3, kRate}, bound));
      scheme->step(pool, forces, StepTime{3, kRate});
      const Vec3Column* extra = extraColumnOf(pool, scheme->readsPreviousPosition());
      const StateBound seen = largestOf(pool, extra);
      EXPECT_LE(seen.position, bound.position);
      EXPECT_LE(seen.velocity, bound.velocity);
      EXPECT_LE(seen.extra, bound.extra);
      EXPECT_LT(started.extra, 4.0 * seen.extra + 1.0);
    }
  }
}

// What the one pass's forms do not cover (a spring reads the position) is not bounded, and a
// bound near the float limit proves nothing: the product a tick would make could overflow.
TEST(StateBound, NoProofBeyondTheFormsOrNearTheFloatLimit) {
  std::unique_ptr<Integrator> euler = makeIntegrator("semi_implicit_euler");
  ParticlePool pool = cornerRows(*euler, formForces(0.5f), 1.0f, 1.0f, 0.0f);
  ForceSet spring;
  spring.add(std::make_unique<AnchorSpring>(Eigen::Vector3f(0.0f, 2.0f, 0.0f), 5.0f, 0.0f));
  const ForceSet forces = formForces(0.5f);
  for (const std::string& name : integratorNames()) {
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
