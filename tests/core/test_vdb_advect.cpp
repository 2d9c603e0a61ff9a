// Advection (v := u(x, t)) through fields/VectorField and fields/AnalyticField: the first-order
// schemes of integrators/Advection, the kill policy, and agreement with OpenVDB's own
// tools::PointAdvect. The fields are baked in memory; nothing is written to disk.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <memory>
#include <string>
#include <vector>

#include "VdbTestData.h"
#include "fields/ForceSet.h"
#include "fields/Gravity.h"
#include "fields/vdb/AnalyticField.h"
#include "fields/vdb/VectorField.h"
#include "integrators/Integrator.h"
#include "particles/ParticlePool.h"
#include "particles/ParticleSystem.h"

namespace tickfx {
namespace {

BakeSettings box(double h, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  BakeSettings b;
  b.voxelSize = h;
  b.min = lo;
  b.max = hi;
  return b;
}

VectorField::Settings advect(VectorField::Outside outside = VectorField::Outside::Background) {
  VectorField::Settings s;
  s.file = "baked";
  s.mode = VectorField::Mode::Advect;
  s.outside = outside;
  return s;
}

std::unique_ptr<VectorField> bakedAdvection(
    const AnalyticField& f, const BakeSettings& b,
    VectorField::Outside outside = VectorField::Outside::Background) {
  return bakeVectorField(f, b, advect(outside));
}

Eigen::Vector3f positionOf(const ParticlePool& pool, std::size_t row) {
  return {pool.position().x[row], pool.position().y[row], pool.position().z[row]};
}
Eigen::Vector3f velocityOf(const ParticlePool& pool, std::size_t row) {
  return {pool.velocity().x[row], pool.velocity().y[row], pool.velocity().z[row]};
}

/// Steps `pool` `ticks` times with `scheme` under `forces`, as ParticleSystem does.
void run(ParticlePool& pool, const std::string& scheme, ForceSet& forces, std::int64_t rate,
         std::int64_t ticks) {
  std::unique_ptr<Integrator> integrator = makeIntegrator(scheme);
  for (std::int64_t k = 0; k < ticks; ++k) {
    forces.beginTick(pool, k);
    integrator->step(pool, forces, StepTime{k, rate});
    pool.markAllStepped();
    forces.endTick(pool, StepTime{k, rate}.stage(2));
    pool.removeDead();
  }
}

ParticlePool onePoint(const Eigen::Vector3f& x, const Eigen::Vector3f& v = {9.f, 9.f, 9.f}) {
  ParticlePool pool(1);
  ParticleInit init;
  init.position = x;
  init.velocity = v;  // ignored by advection: the field prescribes velocity
  pool.spawn(init, 0);
  return pool;
}

// ---- schemes ----------------------------------------------------------------------------------

TEST(VdbAdvect, UniformFieldCarriesParticlesExactly) {
  const Eigen::Vector3d u(0.5, -1.0, 0.25);
  const auto bake = box(0.25, Eigen::Vector3d::Constant(-4), Eigen::Vector3d::Constant(4));
  const std::int64_t rate = 24, ticks = 48;
  const float h = StepTime{0, rate}.dt();
  for (const std::string& scheme : integratorNames()) {
    ForceSet sampled, analytic;
    sampled.add(bakedAdvection(AnalyticField::uniform(u), bake));
    analytic.add(std::make_unique<AnalyticForce>(AnalyticField::uniform(u),
                                                 AnalyticForce::Mode::Advect, 1.0f));
    ASSERT_TRUE(sampled.prescribesVelocity());
    const Eigen::Vector3f x0(0.1f, 0.2f, -0.3f);
    ParticlePool a = onePoint(x0), b = onePoint(x0);
    run(a, scheme, sampled, rate, ticks);
    run(b, scheme, analytic, rate, ticks);
    EXPECT_EQ(positionOf(a, 0), positionOf(b, 0)) << scheme;
    EXPECT_EQ(velocityOf(a, 0), velocityOf(b, 0)) << scheme;
    // The velocity the step used, not the 9 m/s the particle was born with.
    EXPECT_NEAR((velocityOf(a, 0) - u.cast<float>()).norm(), 0.0f, 1e-6f) << scheme;
    Eigen::Vector3f expected = x0;
    for (std::int64_t k = 0; k < ticks; ++k) {
      for (int c = 0; c < 3; ++c) expected[c] += h * static_cast<float>(u[c]);
    }
    if (scheme == "rk4") {  // (h·6u)/6 is not h·u to the last bit
      EXPECT_LT((positionOf(a, 0) - expected).norm(), 1e-6f) << scheme;
    } else {
      EXPECT_EQ(positionOf(a, 0), expected) << scheme;
    }
  }
}

/// The amplification factor of `scheme` on x' = iωx for one step, θ = ω·h.
std::complex<double> amplification(const std::string& scheme, double theta) {
  const std::complex<double> z(0.0, theta);
  if (scheme == "explicit_euler" || scheme == "semi_implicit_euler" ||
      scheme == "position_verlet") {
    return 1.0 + z;
  }
  if (scheme == "midpoint" || scheme == "velocity_verlet") return 1.0 + z + z * z / 2.0;
  return 1.0 + z + z * z / 2.0 + z * z * z / 6.0 + z * z * z * z / 24.0;  // rk4
}

TEST(VdbAdvect, RigidVortexFollowsEachSchemesExactDiscreteOrbit) {
  // u = ω ẑ × x: the exact orbit is the unit circle. Each scheme multiplies x + iy by its
  // amplification factor G(iωh) every step, so after N steps the radius is |G|^N: Euler spirals
  // out at √(1 + θ²), the second-order schemes at (1 + θ⁴/4)^½, RK4 spirals in at
  // (1 − θ⁶/72 + θ⁸/576)^½. Trilinear sampling reproduces the affine field, so the sampled run
  // must land on that orbit to float rounding.
  const double omega = 1.0;
  const AnalyticField vortex = AnalyticField::vortex({0, 0, 0}, {0, 0, 1}, omega);
  const auto bake = box(0.125, {-2.5, -2.5, -0.5}, {2.5, 2.5, 0.5});
  for (const std::string& scheme : integratorNames()) {
    // A step long enough that every scheme's radius error stands well above float rounding.
    const std::int64_t rate = scheme == "rk4" ? 2 : 10;
    const std::int64_t ticks = scheme == "rk4" ? 40 : 100;
    const double theta = omega * static_cast<double>(StepTime{0, rate}.dt());
    ForceSet forces;
    forces.add(bakedAdvection(vortex, bake));
    ParticlePool pool = onePoint({1.0f, 0.0f, 0.0f});
    run(pool, scheme, forces, rate, ticks);

    const std::complex<double> end = std::pow(amplification(scheme, theta), double(ticks));
    const Eigen::Vector3f x = positionOf(pool, 0);
    EXPECT_NEAR(x.x(), end.real(), 2e-5) << scheme;
    EXPECT_NEAR(x.y(), end.imag(), 2e-5) << scheme;
    EXPECT_EQ(x.z(), 0.0f) << scheme;
    const double radius = std::hypot(double(x.x()), double(x.y()));
    const double g2 = std::norm(amplification(scheme, theta));  // |G|²
    EXPECT_NEAR(radius, std::pow(g2, ticks / 2.0), 2e-5) << scheme;
    if (scheme == "rk4") {
      EXPECT_NEAR(g2, 1.0 - std::pow(theta, 6) / 72.0 + std::pow(theta, 8) / 576.0, 1e-15);
      EXPECT_LT(radius, 1.0 - 3e-3) << "RK4's inward spiral must be visible at θ = 0.5";
    } else if (scheme == "midpoint" || scheme == "velocity_verlet") {
      EXPECT_NEAR(g2, 1.0 + std::pow(theta, 4) / 4.0, 1e-15);
      EXPECT_GT(radius, 1.0 + 1e-3) << scheme;
    } else {
      EXPECT_NEAR(g2, 1.0 + theta * theta, 1e-15);
      EXPECT_GT(radius, 1.6) << scheme;  // (1.01)^50
    }
  }
}

TEST(VdbAdvect, EvolvingCurlNoiseIsSampledAtEachStagesTime) {
  // An evolving field baked as a sequence: RK4's stages read the frames around t, t + h/2 and
  // t + h. With one frame per tick the runs of a baked sequence and of the analytic field agree
  // to the interpolation error, and differ clearly from the same field frozen at t = 0.
  const AnalyticField noise = AnalyticField::curlNoise(7, 3.0, 1.0, 4, 2.0);
  const auto bake = box(0.1, Eigen::Vector3d::Constant(-1.2), Eigen::Vector3d::Constant(1.2));
  VectorField::Settings seq = advect();
  seq.fps = 24.0;
  seq.firstFrame = 1;
  seq.lastFrame = 25;
  ForceSet sampled, analytic, frozen;
  sampled.add(bakeVectorField(noise, bake, seq));
  analytic.add(std::make_unique<AnalyticForce>(noise, AnalyticForce::Mode::Advect, 1.0f));
  frozen.add(bakeVectorField(noise, bake, advect()));
  const Eigen::Vector3f x0(0.1f, -0.2f, 0.3f);
  ParticlePool a = onePoint(x0), b = onePoint(x0), c = onePoint(x0);
  run(a, "rk4", sampled, 24, 24);
  run(b, "rk4", analytic, 24, 24);
  run(c, "rk4", frozen, 24, 24);
  const float travelled = (positionOf(b, 0) - x0).norm();
  ASSERT_GT(travelled, 0.2f);
  // Trilinear in space (h = 0.1 m) and linear in time (1/24 s): a few millimetres.
  // Seen: 0.228 m travelled, 1.2 mm from the analytic run, 187 mm for the frozen field.
  EXPECT_LT((positionOf(a, 0) - positionOf(b, 0)).norm(), 3e-3f);
  EXPECT_GT((positionOf(c, 0) - positionOf(b, 0)).norm(), 0.1f);
}

// ---- kill -------------------------------------------------------------------------------------

TEST(VdbAdvect, KillRemovesParticlesWhenTheyLeaveTheActiveVoxels) {
  // Active voxel centres x = −1 … 1 (h = 0.25); the voxel nearest to x is active up to
  // x < 1.125. At 1 m/s and 10 Hz a particle born at x = 0 is at 0.1·k after tick k: still
  // inside after tick 11 (1.1 m), flagged at the end of tick 12 (1.2 m) and removed then.
  SystemSettings settings;
  settings.stepRateHz = 10;
  settings.integrator = "explicit_euler";
  EmitterSettings emitter;
  emitter.bursts = {Burst{0.0, 3}};
  ForceSet forces;
  forces.add(bakedAdvection(AnalyticField::uniform({1.0, 0.0, 0.0}),
                            box(0.25, Eigen::Vector3d::Constant(-1), Eigen::Vector3d::Constant(1)),
                            VectorField::Outside::Kill));
  ParticleSystem system(settings, {emitter}, std::move(forces));
  system.stepTicks(11);
  EXPECT_EQ(system.pool().size(), 3u);
  EXPECT_NEAR(system.pool().position().x[0], 1.1f, 1e-6f);
  system.step();
  EXPECT_EQ(system.pool().size(), 0u);
}

TEST(VdbAdvect, KillAddsNothingOutsideDuringTheStep) {
  // A particle outside the active voxels is not carried by the background (here 5 m/s): the
  // step samples zero there, then the end of the tick removes it.
  auto bake = box(0.25, Eigen::Vector3d::Constant(-1), Eigen::Vector3d::Constant(1));
  bake.background = Eigen::Vector3f(5.0f, 0.0f, 0.0f);
  const AnalyticField u = AnalyticField::uniform({1.0, 0.0, 0.0});
  ForceSet kill, background;
  kill.add(bakedAdvection(u, bake, VectorField::Outside::Kill));
  background.add(bakedAdvection(u, bake));
  ParticlePool a(2), b(2);
  for (ParticlePool* pool : {&a, &b}) {
    ParticleInit init;
    pool->spawn(init, 0);  // inside
    init.position = Eigen::Vector3f(3.0f, 0.0f, 0.0f);
    pool->spawn(init, 0);  // outside
  }
  std::unique_ptr<Integrator> euler = makeIntegrator("explicit_euler");
  euler->step(a, kill, StepTime{0, 10});
  euler->step(b, background, StepTime{0, 10});
  EXPECT_EQ(positionOf(a, 1).x(), 3.0f);
  EXPECT_EQ(positionOf(b, 1).x(), 3.5f);
  kill.endTick(a, TickInstant{0, 2, 10});  // the end of tick 0 at 10 Hz: 0.1 s
  EXPECT_EQ(a.dead()[0], 0);
  EXPECT_EQ(a.dead()[1], 1);
  a.removeDead();
  ASSERT_EQ(a.size(), 1u);
  EXPECT_EQ(positionOf(a, 0).x(), 0.1f);
}

// One-voxel grids (voxels of 0.5 m), the voxel of frame f active at x = activeX[f]: a kill region
// that moves between frames.
std::unique_ptr<VectorField> activeAt(const VectorField::Settings& s,
                                      const std::vector<float>& activeX) {
  std::vector<vdb_test::Coord> voxels;
  for (const float x : activeX) voxels.push_back({static_cast<int>(x / 0.5f), 0, 0});
  return vdb_test::oneVoxelFrames(s, 0.5, voxels);
}

// Regression (issue 10, item 4): a sequence's frame was ⌊t·fps⌋ in double. At t = 1/49 s and
// fps = 49, 1/49 · 49 = 0.9999999999999999: frame 1's active region decided the kill test at the
// end of tick 0 instead of frame 2's, and a particle inside frame 2's region died.
TEST(VdbAdvect, ASequencesFrameComesFromTheIntegerClock) {
  VectorField::Settings s = advect(VectorField::Outside::Kill);
  s.fps = 49.0;
  s.firstFrame = 1;
  s.lastFrame = 2;
  const std::unique_ptr<VectorField> field = activeAt(s, {0.0f, 3.0f});
  ParticlePool pool(1);
  ParticleInit init;
  init.position = Eigen::Vector3f(3.0f, 0.0f, 0.0f);
  pool.spawn(init, 0);
  ForceSet forces;
  VectorField::Frames f = field->framesAt(TickInstant{0, 2, 49});  // the end of tick 0: 1/49 s
  EXPECT_EQ(f.first, 1u);
  EXPECT_EQ(f.second, 1u);
  VectorField& killer = static_cast<VectorField&>(forces.add(activeAt(s, {0.0f, 3.0f})));
  killer.endTick(pool, TickInstant{0, 2, 49});
  EXPECT_EQ(pool.dead()[0], 0) << "inside frame 2's region at frame 2's time";
  killer.endTick(pool, TickInstant{0, 1, 49});  // half a tick: frame 1 still decides
  EXPECT_EQ(pool.dead()[0], 1);
  f = field->framesAt(TickInstant{0, 1, 49});
  EXPECT_EQ(f.first, 0u);
  EXPECT_EQ(f.second, 1u);
  EXPECT_EQ(f.weight, 0.5f);

  // 24 Hz ticks through a 30 fps sequence: tick 196 is 8 1/6 s, frame 245 exactly (in double,
  // 196/24 · 30 = 244.99999999999997). Weights are the exact fraction rounded once.
  VectorField::Settings many = advect();
  many.fps = 30.0;
  many.firstFrame = 0;
  many.lastFrame = 299;
  const std::unique_ptr<VectorField> sequence = activeAt(many, std::vector<float>(300, 0.0f));
  f = sequence->framesAt(TickInstant{196, 0, 24});
  EXPECT_EQ(f.first, 245u);
  EXPECT_EQ(f.weight, 0.0f);
  f = sequence->framesAt(TickInstant{197, 1, 24});  // 8.229166... s: 246.875 frames
  EXPECT_EQ(f.first, 246u);
  EXPECT_EQ(f.weight, 0.875f);
  f = sequence->framesAt(TickInstant{1, 0, 7});  // 30/7 = 4 + 2/7
  EXPECT_EQ(f.first, 4u);
  EXPECT_EQ(f.weight, 2.0f / 7.0f);
  f = sequence->framesAt(TickInstant{1000, 0, 24});  // past the last frame: clamped
  EXPECT_EQ(f.first, 299u);
  EXPECT_EQ(f.second, 299u);
}

// The system asks a kill region at its tick's end, as the module is told to be asked: frame 2's
// region (x = 3) decides at the end of tick 0 (1/49 s), not frame 1's (x = 0) at its middle. A
// mutant of ParticleSystem's endTick instant survived the tests before this one.
TEST(VdbAdvect, TheSystemAsksTheKillRegionAtTheTicksEnd) {
  VectorField::Settings s = advect(VectorField::Outside::Kill);
  s.fps = 49.0;
  s.firstFrame = 1;
  s.lastFrame = 2;
  ForceSet forces;
  forces.add(activeAt(s, {0.0f, 3.0f}));
  SystemSettings settings;
  settings.stepRateHz = 49;
  settings.threads = 1;
  ParticleSystem system(settings, {}, std::move(forces));
  ParticleInit inside, outside;
  inside.position = Eigen::Vector3f(3.0f, 0.0f, 0.0f);
  outside.position = Eigen::Vector3f(0.0f, 0.0f, 0.0f);
  system.editPool().spawn(inside, 0);
  system.editPool().spawn(outside, 0);
  system.step();
  ASSERT_EQ(system.pool().size(), 1u);
  EXPECT_EQ(system.pool().id()[0], 0u) << "the particle in frame 2's region lives";
}

// ---- rules ------------------------------------------------------------------------------------

TEST(VdbAdvect, CannotBeMixedWithAccelerationForces) {
  const auto bake = box(0.5, Eigen::Vector3d::Constant(-1), Eigen::Vector3d::Constant(1));
  const std::string message =
      "vector_field in advect mode sets the velocity, so the gravity force would be ignored: an "
      "advected effect cannot have acceleration forces (use mode \"drag\" to pull particles "
      "toward the field instead)";
  {
    ForceSet set;
    set.add(std::make_unique<Gravity>(Eigen::Vector3f(0.0f, -9.81f, 0.0f)));
    try {
      set.add(bakedAdvection(AnalyticField::uniform({1, 0, 0}), bake));
      ADD_FAILURE() << "no error";
    } catch (const std::invalid_argument& e) {
      EXPECT_EQ(std::string(e.what()), message);
    }
  }
  ForceSet set;
  set.add(bakedAdvection(AnalyticField::uniform({1, 0, 0}), bake));
  set.add(bakedAdvection(AnalyticField::uniform({0, 1, 0}), bake));  // flows superpose
  EXPECT_THROW(set.add(std::make_unique<Gravity>(Eigen::Vector3f(0.0f, -9.81f, 0.0f))),
               std::invalid_argument);
  ParticlePool pool = onePoint({0.0f, 0.0f, 0.0f});
  run(pool, "explicit_euler", set, 10, 1);
  EXPECT_EQ(velocityOf(pool, 0), Eigen::Vector3f(1.0f, 1.0f, 0.0f));
}

TEST(VdbAdvect, PinnedParticlesStayPut) {
  const auto bake = box(0.5, Eigen::Vector3d::Constant(-1), Eigen::Vector3d::Constant(1));
  ForceSet forces;
  forces.add(bakedAdvection(AnalyticField::uniform({1, 0, 0}), bake));
  ParticlePool pool(1);
  ParticleInit init;
  init.mass = std::numeric_limits<float>::infinity();
  pool.spawn(init, 0);
  run(pool, "rk4", forces, 10, 5);
  EXPECT_EQ(positionOf(pool, 0), Eigen::Vector3f::Zero());
  EXPECT_EQ(velocityOf(pool, 0), Eigen::Vector3f::Zero());
}

// ---- agreement with openvdb::tools::PointAdvect ------------------------------------------------

/// 10⁴ points advected through a baked curl-noise field for 48 steps by tickfx (through the
/// integrator `scheme`) and by PointAdvect at `order`; returns the largest difference in metres.
float pointAdvectDifference(const std::string& scheme, unsigned order, bool threaded) {
  const AnalyticField noise = AnalyticField::curlNoise(11, 4.0, 1.0, 4);
  const auto bake = box(0.05, Eigen::Vector3d::Constant(-1.2), Eigen::Vector3d::Constant(1.2));
  // Each bakes the field for itself: PointAdvect the bare grid, tickfx its VectorField.
  std::unique_ptr<VectorField> field = bakeVectorField(noise, bake, advect());

  const std::size_t n = 10'000;
  ParticlePool pool(n);
  vdb_test::Positions points(n);
  for (std::size_t i = 0; i < n; ++i) {
    // A Weyl sequence in [−0.8, 0.8]³: deterministic and well spread.
    ParticleInit init;
    const double a[3] = {0.7548776662466927, 0.5698402909980532, 0.3611333928711215};
    for (int c = 0; c < 3; ++c) {
      init.position[c] = static_cast<float>(-0.8 + 1.6 * std::fmod(0.5 + a[c] * (i + 1), 1.0));
    }
    pool.spawn(init, 0);
    points[i] = {init.position.x(), init.position.y(), init.position.z()};
  }
  ForceSet forces;
  forces.add(std::move(field));
  const std::int64_t rate = 24, ticks = 48;
  run(pool, scheme, forces, rate, ticks);

  std::vector<float> steps;
  for (std::int64_t k = 0; k < ticks; ++k) steps.push_back(StepTime{k, rate}.dt());
  points = vdb_test::advectWithPointAdvect(noise, bake, points, steps, order, threaded);

  float worst = 0.0f;
  for (std::size_t i = 0; i < n; ++i) {
    for (int c = 0; c < 3; ++c) {
      worst = std::max(worst, std::abs(pool.position()[c][static_cast<Eigen::Index>(i)] -
                                       points[i][static_cast<std::size_t>(c)]));
    }
  }
  return worst;
}

TEST(VdbAdvect, AgreesBitwiseWithPointAdvectFirstOrder) {
  // The same samples in the same float operations: not close, identical.
  EXPECT_EQ(pointAdvectDifference("explicit_euler", 1, false), 0.0f);
  EXPECT_EQ(pointAdvectDifference("semi_implicit_euler", 1, true), 0.0f);
}

TEST(VdbAdvect, AgreesBitwiseWithPointAdvectSecondOrder) {
  EXPECT_EQ(pointAdvectDifference("midpoint", 2, true), 0.0f);
}

TEST(VdbAdvect, AgreesBitwiseWithPointAdvectFourthOrder) {
  EXPECT_EQ(pointAdvectDifference("rk4", 4, false), 0.0f);
  EXPECT_EQ(pointAdvectDifference("rk4", 4, true), 0.0f);
}

TEST(VdbAdvect, DiffersFromPointAdvectOfAnotherOrder) {
  // The comparison can fail: RK4 against PointAdvect's first order parts by millimetres.
  EXPECT_GT(pointAdvectDifference("rk4", 1, false), 1e-3f);
}

}  // namespace
}  // namespace tickfx
