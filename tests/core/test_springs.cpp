// Spring networks (fields/SpringNetwork) and the structures built on them (particles/Structure).
//
// Physics: a rope's energy under explicit Euler, semi-implicit Euler and velocity Verlet, held to
// the closed forms of each scheme on the rope's normal modes; the period and the damping rate of a
// two-particle spring; the static shape of a damped hanging chain; a cloth coming to rest.
// Bookkeeping: what buildStructure makes, springs whose ends die or are not born yet, breaking,
// pinning. Bits: the two ends of a spring get exactly opposite forces, and the state is the same
// for 1, 2 and 3 threads.
//
// Energies are computed in double from the pool and the network's springs (ids mapped to rows):
// kinetic ½Σm·v² over free particles, spring ½Σk·(|d| − L)², gravity Σm·g·y where present.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <numbers>
#include <ostream>
#include <set>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <vector>

#include "CoreTestSupport.h"
#include "fields/SpringNetwork.h"
#include "particles/NeighbourPairs.h"
#include "particles/ParallelFor.h"
#include "particles/Random.h"
#include "particles/StateHash.h"
#include "particles/Structure.h"

namespace tickfx {
namespace {

using test::bitsOf;
using test::floatDt;
using test::kFloatU;

constexpr double kPi = std::numbers::pi;
constexpr double kInf = std::numeric_limits<double>::infinity();
// The gravity of test::gravityOnly(), as the float the simulation uses.
const double kG = static_cast<double>(9.81f);

Eigen::Index ix(std::size_t row) { return static_cast<Eigen::Index>(row); }

Eigen::Vector3d positionOf(const ParticlePool& pool, std::size_t r) {
  return {pool.position().x[ix(r)], pool.position().y[ix(r)], pool.position().z[ix(r)]};
}

Eigen::Vector3d velocityOf(const ParticlePool& pool, std::size_t r) {
  return {pool.velocity().x[ix(r)], pool.velocity().y[ix(r)], pool.velocity().z[ix(r)]};
}

bool pinned(const ParticlePool& pool, std::size_t r) {
  return inverseMassOf(pool.mass()[ix(r)]) == 0.0f;
}

// ---- energies ----------------------------------------------------------------------------------

struct Energy {
  double kinetic = 0.0;
  double spring = 0.0;
  double gravity = 0.0;
  double total() const { return kinetic + spring + gravity; }
};

std::unordered_map<std::uint64_t, std::size_t> rowsById(const ParticlePool& pool) {
  std::unordered_map<std::uint64_t, std::size_t> rows;
  for (std::size_t r = 0; r < pool.size(); ++r) rows.emplace(pool.id()[r], r);
  return rows;
}

/// `g`: gravity along −y in m/s² (0 for none); the potential is m·g·y. Pinned particles (m = ∞,
/// v = 0) carry no kinetic energy and, never moving, only a constant potential, left out.
Energy energyOf(const ParticlePool& pool, const SpringNetwork& network, double g = 0.0) {
  Energy e;
  for (std::size_t r = 0; r < pool.size(); ++r) {
    if (pinned(pool, r)) continue;
    const double m = pool.mass()[ix(r)];
    e.kinetic += 0.5 * m * velocityOf(pool, r).squaredNorm();
    e.gravity += m * g * positionOf(pool, r).y();
  }
  const auto rows = rowsById(pool);
  for (const Spring& s : network.springs()) {
    const auto a = rows.find(s.a), b = rows.find(s.b);
    if (a == rows.end() || b == rows.end()) continue;
    const double stretch =
        (positionOf(pool, b->second) - positionOf(pool, a->second)).norm() - s.restLength;
    e.spring += 0.5 * static_cast<double>(s.stiffness) * stretch * stretch;
  }
  return e;
}

/// The same for a structure as built, before tick 0 (spring ends are indices into particles).
Energy energyOf(const StructureBuild& build, double g = 0.0) {
  Energy e;
  for (const ParticleInit& p : build.particles) {
    if (std::isinf(p.mass)) continue;
    e.kinetic += 0.5 * p.mass * p.velocity.cast<double>().squaredNorm();
    e.gravity += p.mass * g * static_cast<double>(p.position.y());
  }
  for (const Spring& s : build.springs) {
    const Eigen::Vector3d d =
        (build.particles[s.b].position - build.particles[s.a].position).cast<double>();
    const double stretch = d.norm() - s.restLength;
    e.spring += 0.5 * static_cast<double>(s.stiffness) * stretch * stretch;
  }
  return e;
}

constexpr std::uint64_t kSeed = 99;

SystemSettings settingsFor(const std::string& integrator, std::int64_t rate, int threads = 1) {
  SystemSettings s;
  s.stepRateHz = rate;
  s.integrator = integrator;
  s.seed = kSeed;
  s.maxParticles = 100'000;
  s.threads = threads;
  return s;
}

SpringNetwork& addNetwork(ForceSet& forces) {
  return static_cast<SpringNetwork&>(forces.add(std::make_unique<SpringNetwork>()));
}

std::string integratorName(const ::testing::TestParamInfo<std::string>& info) { return info.param; }

// Each tick rounds every float of the state a few times; as in test_oscillator, 4u per tick bounds
// what that does to a quadratic form of the state.
double roundOff(std::int64_t ticks) { return 4.0 * static_cast<double>(ticks) * kFloatU; }

// ---- what buildStructure makes -----------------------------------------------------------------

TEST(BuildStructure, RopeIsEvenlySpacedJoinedNeighbourToNeighbourAndPinnedAtItsStart) {
  StructureSettings s;
  RopeShape rope;
  rope.start = Eigen::Vector3d(1.0, 2.0, 3.0);
  rope.end = Eigen::Vector3d(1.0, -1.0, 7.0);  // 5 m away
  rope.count = 6;
  s.shape = rope;
  s.mass = 0.25;
  s.stiffness = 80.0;
  s.damping = 0.5;
  s.breakRatio = 1.75;
  s.velocity = Eigen::Vector3d(0.0, 0.0, 2.0);
  const StructureBuild b = buildStructure(s, kSeed, 0);
  ASSERT_EQ(b.particles.size(), 6u);
  ASSERT_EQ(b.springs.size(), 5u);
  for (int i = 0; i < 6; ++i) {
    const Eigen::Vector3d expected = rope.start + (rope.end - rope.start) * (i / 5.0);
    EXPECT_LT((b.particles[i].position.cast<double>() - expected).norm(), 1e-6) << i;
    if (i == 0) {
      EXPECT_TRUE(std::isinf(b.particles[i].mass));
      EXPECT_EQ(b.particles[i].velocity, Eigen::Vector3f::Zero());
    } else {
      EXPECT_EQ(b.particles[i].mass, 0.25f) << i;
      EXPECT_EQ(b.particles[i].velocity, Eigen::Vector3f(0.0f, 0.0f, 2.0f)) << i;
    }
  }
  for (const Spring& sp : b.springs) {
    EXPECT_EQ(std::max(sp.a, sp.b) - std::min(sp.a, sp.b), 1u);
    EXPECT_NEAR(sp.restLength, 1.0, 1e-6);
    EXPECT_EQ(sp.stiffness, 80.0f);
    EXPECT_EQ(sp.damping, 0.5f);
    EXPECT_EQ(sp.breakRatio, 1.75f);
  }
  rope.count = 1;
  s.shape = rope;
  EXPECT_THROW(buildStructure(s, kSeed, 0), std::invalid_argument);
}

TEST(BuildStructure, ValidateNamesEachProblemByItsKeyAndBuildThrowsTheFirst) {
  StructureSettings s;
  RopeShape rope;
  rope.start = Eigen::Vector3d(1e-200, 0.0, 0.0);
  rope.end = Eigen::Vector3d(0.0, 1e-200, 0.0);  // 1.41e-200 m apart: no length in double
  s.shape = rope;
  s.breakRatio = 0.5;
  const SettingProblems problems = s.validate();
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_EQ(problems[0].text(),
            "break_ratio: 0.5 is out of range (expected 0 (never breaks) or a ratio of the rest "
            "length > 1)");
  EXPECT_EQ(problems[1].text(),
            "end: is 1.41e-200 m from start, too close to give the rope a length in double "
            "precision (expected [x, y, z] in metres, at least 1.5e-154 m from start)");
  try {
    buildStructure(s, kSeed, 0);
    ADD_FAILURE() << "built";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "rope " + problems[0].text());
  }
  // A cloth's spacing must be a finite length.
  for (const double spacing : {0.0, -0.5, std::numeric_limits<double>::infinity()}) {
    ClothShape bad;
    bad.spacing = spacing;
    StructureSettings withCloth;
    withCloth.shape = bad;
    ASSERT_EQ(withCloth.validate().size(), 1u) << spacing;
    EXPECT_EQ(withCloth.validate()[0].key, "spacing");
  }
  // The same end as start, away from the origin: no length at all.
  rope.start = rope.end = Eigen::Vector3d(1.0, 2.0, 3.0);
  s = StructureSettings{};
  s.shape = rope;
  ASSERT_EQ(s.validate().size(), 1u);
  EXPECT_EQ(s.validate()[0].text(),
            "end: is 0 m from start, too close to give the rope a length in double precision "
            "(expected [x, y, z] in metres, at least 1.5e-154 m from start)");
  // Exactly the shortest length: its square, 2^-1022, is the smallest normal double.
  rope.start = Eigen::Vector3d::Zero();
  rope.end = Eigen::Vector3d(0x1p-511, 0.0, 0.0);
  s.shape = rope;
  EXPECT_TRUE(s.validate().empty());
  // Cloth axes: each must normalise, and then not be parallel.
  ClothShape cloth;
  cloth.axisU = Eigen::Vector3d(1e-200, 0.0, 0.0);
  s = StructureSettings{};
  s.shape = cloth;
  ASSERT_EQ(s.validate().size(), 1u);
  EXPECT_EQ(s.validate()[0].key, "axis_u");
  EXPECT_FALSE(clothAxesParallel(cloth));  // too short to have a direction at all
  cloth.axisU = Eigen::Vector3d(0.0, 3.0, 0.0);
  s.shape = cloth;
  EXPECT_TRUE(clothAxesParallel(cloth));
  ASSERT_EQ(s.validate().size(), 1u);
  EXPECT_EQ(
      s.validate()[0].text(),
      "axis_v: is parallel to axis_u (expected a direction [x, y, z] not parallel to axis_u)");
  // A side below 2 is the one problem: the particle count is judged only for sides that can be.
  cloth = ClothShape{};
  cloth.width = 2'000'000;
  cloth.height = 1;
  s.shape = cloth;
  ASSERT_EQ(s.validate().size(), 1u);
  EXPECT_EQ(s.validate()[0].text(),
            "height: 1 is out of range (expected particles, an integer of at least 2)");
  cloth.width = 1;
  cloth.height = 2'000'000;
  s.shape = cloth;
  ASSERT_EQ(s.validate().size(), 1u);
  EXPECT_EQ(s.validate()[0].key, "width");
  // The smallest sides that can be too many: 2 x 500001.
  cloth.width = 2;
  cloth.height = 500'001;
  s.shape = cloth;
  ASSERT_EQ(s.validate().size(), 1u);
  EXPECT_EQ(s.validate()[0].text(),
            "height: 2 x 500001 = 1000002 particles are too many (expected width x height at most "
            "1000000)");
  cloth.height = 500'000;
  s.shape = cloth;
  EXPECT_TRUE(s.validate().empty());
  // A cluster's radii must be positive: 0 is refused, the smallest positive double is not.
  ClusterShape cluster;
  cluster.linkRadius = 0.0;
  s = StructureSettings{};
  s.shape = cluster;
  ASSERT_EQ(s.validate().size(), 1u);
  EXPECT_EQ(s.validate()[0].text(),
            "link_radius: 0 is out of range (expected metres, a finite number > 0)");
  cluster.linkRadius = std::numeric_limits<double>::denorm_min();
  s.shape = cluster;
  EXPECT_TRUE(s.validate().empty());
  cluster.radius = 0.0;
  cluster.count = 1'000'001;
  s.shape = cluster;
  ASSERT_EQ(s.validate().size(), 2u);
  EXPECT_EQ(s.validate()[0].text(),
            "count: 1000001 is out of range (expected particles, an integer from 1 to 1000000)");
  EXPECT_EQ(s.validate()[1].text(),
            "radius: 0 is out of range (expected metres, a finite number > 0)");
  cluster.radius = std::numeric_limits<double>::denorm_min();
  cluster.count = 1'000'000;
  s.shape = cluster;
  EXPECT_TRUE(s.validate().empty());
  s = StructureSettings{};
  s.lifetime = 0.0;
  ASSERT_EQ(s.validate().size(), 1u);
  EXPECT_EQ(s.validate()[0].text(), "lifetime: 0 is out of range (expected seconds, a number > 0)");
  // A structure's birth time is its own to check (the system turns it into a tick).
  s = StructureSettings{};
  s.time = -1.0;
  ASSERT_EQ(s.validate().size(), 1u);
  EXPECT_EQ(s.validate()[0].key, "time");
}

// ---- clusters: the pairs within the link radius (NeighbourPairs) ----------------------------

// `n` points uniform in a ball of `radius` about `center`, from the counter-based generator.
std::vector<Eigen::Vector3d> pointsInBall(int n, double radius,
                                          const Eigen::Vector3d& center = Eigen::Vector3d::Zero()) {
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < n; ++i) {
    const auto u = [&](std::uint32_t purpose) {
      return randomUniform(RandomKey{kSeed, 7, static_cast<std::uint64_t>(i), purpose});
    };
    const double z = 1.0 - 2.0 * u(1), rxy = std::sqrt(std::max(0.0, 1.0 - z * z));
    const double phi = 2.0 * kPi * u(2), r = radius * std::cbrt(u(3));
    points.push_back(center + r * Eigen::Vector3d(rxy * std::cos(phi), rxy * std::sin(phi), z));
  }
  return points;
}

// Every pair, compared as neighbourPairs promises: (points[j] − points[i]).norm() <= distance.
std::vector<std::pair<int, int>> bruteForcePairs(const std::vector<Eigen::Vector3d>& points,
                                                 double distance) {
  std::vector<std::pair<int, int>> pairs;
  const auto n = static_cast<int>(points.size());
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n; ++j) {
      if ((points[j] - points[i]).norm() <= distance) pairs.emplace_back(i, j);
    }
  }
  return pairs;
}

// Regression (issue 10, item 16): rest lengths came from the double positions while particles
// are float, so a cloth far from the origin started under stress and moved on its own. From the
// stored floats, a structure at rest under no force stays exactly at rest, wherever it is.
TEST(BuildStructure, AStructureFarFromTheOriginStartsUnstressed) {
  for (const Eigen::Vector3d& origin :
       {Eigen::Vector3d(0.0, 0.0, 0.0), Eigen::Vector3d(1.0e4, -3.0e3, 7.7e3),
        Eigen::Vector3d(123.456, 0.1, -987.6)}) {
    StructureSettings cloth;
    ClothShape shape;
    shape.origin = origin;
    shape.width = 12;
    shape.height = 9;
    shape.spacing = 0.1;
    shape.pins = ClothPins::None;
    cloth.shape = shape;
    cloth.stiffness = 1000.0;
    cloth.mass = 0.01;
    ParticleSystem system(test::referenceSettings(), {}, ForceSet{}, {cloth});
    system.stepTicks(30);
    const ParticlePool& pool = system.pool();
    ASSERT_EQ(pool.size(), 108u);
    for (int c = 0; c < 3; ++c) {
      EXPECT_TRUE((pool.velocity()[c].head(108) == 0.0f).all())
          << "a cloth at " << origin.transpose() << " moved by itself";
    }
  }
}

TEST(NeighbourPairs, SameListAsComparingEveryPair) {
  const std::vector<Eigen::Vector3d> ball = pointsInBall(400, 1.0, Eigen::Vector3d(3.0, -2.0, 1.0));
  // From chance pairs to every pair joined, and a distance far below any gap.
  for (const double distance : {1e-30, 0.05, 0.17, 0.5, 1.3, 2.5}) {
    const std::vector<std::pair<int, int>> expected = bruteForcePairs(ball, distance);
    EXPECT_EQ(neighbourPairs(ball, distance), expected) << distance;
    if (distance == 0.17) {
      // 399 · (x³ − 9x⁴/16 + x⁶/32) = 1.77 neighbours a point at x = 0.17 (clusterNeighbours):
      // about 355 pairs.
      EXPECT_GT(expected.size(), 300u);
    }
    if (distance == 2.5) {
      EXPECT_EQ(expected.size(), 400u * 399u / 2u);
    }
  }
  // Pairs exactly `distance` apart along the axes, where a cell a hair too narrow would part
  // them, on a lattice shifted off the cell grid's origin; and points that coincide, found even
  // with a link radius of 1e-30.
  std::vector<Eigen::Vector3d> lattice;
  for (int x = 0; x < 7; ++x) {
    for (int y = 0; y < 6; ++y) {
      for (int z = 0; z < 5; ++z) lattice.push_back(Eigen::Vector3d(x, y, z) * 0.1 + ball[x]);
    }
  }
  for (const double distance : {0.1, 0.1 * std::sqrt(2.0), 0.2, 0.3}) {
    EXPECT_EQ(neighbourPairs(lattice, distance), bruteForcePairs(lattice, distance)) << distance;
  }
  std::vector<Eigen::Vector3d> repeated(ball.begin(), ball.begin() + 100);
  repeated.insert(repeated.end(), ball.begin() + 50, ball.begin() + 150);
  const std::vector<std::pair<int, int>> twins = neighbourPairs(repeated, 1e-30);
  EXPECT_EQ(twins, bruteForcePairs(repeated, 1e-30));
  EXPECT_EQ(twins.size(), 50u);  // ball[50..99] twice
  // Degenerate boxes: one point, every point in one place, points along a line.
  EXPECT_TRUE(neighbourPairs({ball[0]}, 1.0).empty());
  const std::vector<Eigen::Vector3d> same(30, ball[3]);
  EXPECT_EQ(neighbourPairs(same, 1e-30).size(), 30u * 29u / 2u);
  std::vector<Eigen::Vector3d> line;
  for (int i = 0; i < 300; ++i) line.push_back(Eigen::Vector3d(0.01 * i, 0.0, 0.0));
  EXPECT_EQ(neighbourPairs(line, 0.025), bruteForcePairs(line, 0.025));
}

// The cells' margin, at the one place it matters: two points exactly `distance` apart whose first
// lies a hair below a cell boundary. With cells exactly `distance` wide they fall in adjacent cells
// only by luck of rounding; with cells 2⁻³⁰ narrower (a margin of the wrong sign) the second lands
// two cells on and the pair is missed. The box is 3 m with 27 points, so the cells are the
// distance wide (1 m) and not widened.
TEST(NeighbourPairs, APairExactlyTheDistanceApartAcrossACellBoundaryIsFound) {
  const double below = 1.0 - 0x1p-30 - 0x1p-40;  // just under a cell 2⁻³⁰ narrower than 1 m
  std::vector<Eigen::Vector3d> points = {Eigen::Vector3d(0.0, 0.0, 0.0),
                                         Eigen::Vector3d(below, 0.0, 0.0),
                                         Eigen::Vector3d(below + 1.0, 0.0, 0.0)};
  ASSERT_EQ((points[2] - points[1]).norm(), 1.0) << "exactly the distance apart";
  while (points.size() < 27) points.push_back(Eigen::Vector3d(3.0, 0.0, 0.0));
  const std::vector<std::pair<int, int>> pairs = neighbourPairs(points, 1.0);
  EXPECT_EQ(pairs, bruteForcePairs(points, 1.0));
  EXPECT_NE(std::find(pairs.begin(), pairs.end(), std::pair<int, int>{1, 2}), pairs.end());
}

TEST(NeighbourPairs, WorkStaysLinearForATinyDistance) {
  // A link radius of 1e-30 in a ball of 1 m: the cells widen to about ∛N per axis instead of
  // 1e30 per metre. 40 000 points fill ∛40000 → 35³ cells, of which the ball covers π/6, so
  // about 1.8 points a cell; each point is compared with the later points of 27 cells, about
  // 27 · 1.8 / 2 ≈ 24 a point, where comparing every pair would be 20 000 a point.
  const std::vector<Eigen::Vector3d> ball = pointsInBall(40'000, 1.0);
  std::uint64_t compared = 0;
  EXPECT_TRUE(neighbourPairs(ball, 1e-30, &compared).empty());
  EXPECT_GT(compared, 0u);
  EXPECT_LT(compared, 40u * 40'000u);
  // At a link radius the cells can be as wide as, the work is a bounded multiple of the pairs
  // found: a point's 27 cells hold 27 / (4π/3) ≈ 6.4 times its neighbours' ball.
  std::uint64_t comparedNear = 0;
  const std::vector<std::pair<int, int>> near = neighbourPairs(ball, 0.1, &comparedNear);
  EXPECT_GT(near.size(), 40'000u);
  EXPECT_LT(comparedNear, 8u * near.size());
}

TEST(BuildStructure, ClusterJoinsThePairsBornWithinTheLinkRadius) {
  StructureSettings s;
  const Eigen::Vector3d center(0.5, 4.0, -1.0);
  s.shape = ClusterShape{center, 0.3, 300, 0.08};
  const StructureBuild b = buildStructure(s, kSeed, 2);
  ASSERT_EQ(b.particles.size(), 300u);
  // The particles are the double positions rounded to float; pairs whose float distance is
  // within a rounding of the link radius could go either way, every other pair is decided.
  const double rounding = 4e-7;
  std::set<std::pair<std::uint64_t, std::uint64_t>> joined;
  for (const Spring& sp : b.springs) {
    EXPECT_LT(sp.a, sp.b);
    joined.emplace(sp.a, sp.b);
  }
  EXPECT_EQ(joined.size(), b.springs.size());  // no pair twice
  EXPECT_TRUE(std::is_sorted(
      b.springs.begin(), b.springs.end(),
      [](const Spring& x, const Spring& y) { return std::pair(x.a, x.b) < std::pair(y.a, y.b); }));
  std::size_t decided = 0;
  for (std::uint64_t i = 0; i < 300; ++i) {
    for (std::uint64_t j = i + 1; j < 300; ++j) {
      const double d =
          (b.particles[j].position.cast<double>() - b.particles[i].position.cast<double>()).norm();
      if (std::abs(d - 0.08) <= rounding) continue;
      ++decided;
      EXPECT_EQ(joined.count({i, j}) == 1, d < 0.08) << i << "-" << j << " at " << d;
    }
  }
  EXPECT_GT(decided, 44'000u);
  EXPECT_GT(b.springs.size(), 300u);
  // A link radius of 1e-30 (valid: > 0) joins nothing, and builds without a cell index beyond
  // the range of an integer (the sanitizer build's float-cast-overflow check guards this).
  s.shape = ClusterShape{center, 0.3, 2000, 1e-30};
  const StructureBuild tiny = buildStructure(s, kSeed, 2);
  EXPECT_EQ(tiny.particles.size(), 2000u);
  EXPECT_TRUE(tiny.springs.empty());
}

// A cluster fills its ball uniformly: by radius (a fraction (r/R)³ within r) and by direction
// (every half-space through the centre holds half). N = 4000: 5 binomial standard deviations at
// p = 1/2 are 0.040, at p = 1/8 0.026.
TEST(BuildStructure, ClusterFillsItsBallUniformly) {
  StructureSettings s;
  const Eigen::Vector3d center(0.5, 4.0, -1.0);
  constexpr int kN = 4000;
  s.shape = ClusterShape{center, 0.3, kN, 1e-30};
  const StructureBuild b = buildStructure(s, kSeed, 1);
  ASSERT_EQ(b.particles.size(), static_cast<std::size_t>(kN));
  const auto fraction = [&](const std::function<bool(const Eigen::Vector3d&)>& f) {
    int count = 0;
    for (const ParticleInit& p : b.particles) count += f(p.position.cast<double>() - center);
    return static_cast<double>(count) / kN;
  };
  EXPECT_EQ(fraction([](const Eigen::Vector3d& d) { return d.norm() <= 0.3 + 1e-6; }), 1.0);
  EXPECT_NEAR(fraction([](const Eigen::Vector3d& d) { return d.norm() <= 0.15; }), 0.125, 0.026);
  for (const Eigen::Vector3d& w :
       {Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(0, 0, 1),
        Eigen::Vector3d(1, 1, 0), Eigen::Vector3d(1, -1, 0), Eigen::Vector3d(1, 1, 1)}) {
    EXPECT_NEAR(fraction([&](const Eigen::Vector3d& d) { return d.dot(w) > 0.0; }), 0.5, 0.04)
        << w.transpose();
  }
}

// Pinned particles have infinite mass (inverse mass 0): each pin setting pins exactly its grid
// points, (col, row) with row 0 at the top.
TEST(BuildStructure, ClothPinsExactlyItsCornersOrItsTopEdge) {
  for (const ClothPins pins : {ClothPins::AllCorners, ClothPins::TopCorners, ClothPins::TopEdge}) {
    StructureSettings s;
    ClothShape cloth;
    cloth.width = 5;
    cloth.height = 4;
    cloth.spacing = 0.25;
    cloth.pins = pins;
    s.shape = cloth;
    const StructureBuild b = buildStructure(s, kSeed, 0);
    ASSERT_EQ(b.particles.size(), 20u);
    for (int row = 0; row < 4; ++row) {
      for (int col = 0; col < 5; ++col) {
        const bool sideCol = col == 0 || col == 4;
        const bool expected = pins == ClothPins::TopEdge      ? row == 0
                              : pins == ClothPins::TopCorners ? row == 0 && sideCol
                                                              : sideCol && (row == 0 || row == 3);
        const float mass = b.particles[static_cast<std::size_t>(row * 5 + col)].mass;
        EXPECT_EQ(std::isinf(mass), expected)
            << "pins " << static_cast<int>(pins) << " at (" << col << ", " << row << ")";
      }
    }
  }
}

TEST(BuildStructure, ClothHasStructuralShearAndBendSpringsWithTheirScales) {
  StructureSettings s;
  ClothShape cloth;
  cloth.width = 7;
  cloth.height = 5;
  cloth.spacing = 0.2;
  cloth.pins = ClothPins::TopCorners;
  s.shape = cloth;
  s.stiffness = 40.0;
  const StructureBuild b = buildStructure(s, kSeed, 0);
  ASSERT_EQ(b.particles.size(), 35u);
  // Structural: 7·4 + 6·5 = 58; shear: 2·6·4 = 48; bend: 7·3 + 5·5 = 46; 152 in all. Every spring
  // joins grid neighbours: (1, 0) or (0, 1) apart, (1, ±1), or (2, 0) or (0, 2), never wrapping
  // from the right edge of one row to the left edge of the next.
  EXPECT_EQ(b.springs.size(), 152u);
  int structural = 0, shear = 0, bend = 0;
  for (const Spring& sp : b.springs) {
    if (std::abs(sp.restLength - 0.2) < 1e-6 && sp.stiffness == 40.0f) {
      ++structural;
    } else if (std::abs(sp.restLength - 0.2 * std::sqrt(2.0)) < 1e-6 && sp.stiffness == 20.0f) {
      ++shear;
    } else if (std::abs(sp.restLength - 0.4) < 1e-6 && sp.stiffness == 4.0f) {
      ++bend;
    } else {
      ADD_FAILURE() << "unexpected spring " << sp.a << "-" << sp.b << " L=" << sp.restLength
                    << " k=" << sp.stiffness;
    }
    // Grid coordinates from the positions (axisU = x, axisV = −y from the origin).
    auto col = [&](std::uint64_t i) {
      return static_cast<int>(std::lround(b.particles[i].position.x() / 0.2));
    };
    auto row = [&](std::uint64_t i) {
      return static_cast<int>(std::lround(-b.particles[i].position.y() / 0.2));
    };
    const int colA = col(sp.a), rowA = row(sp.a), colB = col(sp.b), rowB = row(sp.b);
    EXPECT_LE(std::abs(colA - colB) + std::abs(rowA - rowB), 2)
        << "spring " << sp.a << "-" << sp.b << ": (" << colA << ", " << rowA << ") to (" << colB
        << ", " << rowB << ")";
    const Eigen::Vector3f d = b.particles[sp.b].position - b.particles[sp.a].position;
    EXPECT_NEAR(d.norm(), sp.restLength, 1e-6) << "springs start at rest";
  }
  EXPECT_EQ(structural, 58);
  EXPECT_EQ(shear, 48);
  EXPECT_EQ(bend, 46);
  // TopCorners: the two ends of the row along axisU from the origin.
  std::vector<Eigen::Vector3f> pins;
  for (const ParticleInit& p : b.particles) {
    if (std::isinf(p.mass)) pins.push_back(p.position);
  }
  ASSERT_EQ(pins.size(), 2u);
  std::sort(pins.begin(), pins.end(), [](const auto& l, const auto& r) { return l.x() < r.x(); });
  EXPECT_EQ(pins[0], Eigen::Vector3f(0.0f, 0.0f, 0.0f));
  EXPECT_LT((pins[1] - Eigen::Vector3f(1.2f, 0.0f, 0.0f)).norm(), 1e-6f);
}

// ---- a rope's energy under three schemes -------------------------------------------------------
//
// 10 particles 2/9 m apart on the x axis, the first pinned; k = 500 N/m, m = 1 kg, no damping, no
// gravity, 60 Hz; every free particle starts at 0.2 m/s along the rope (E0 = 0.18 J). Nothing
// leaves the x axis (d has no y or z component), so while no spring is compressed through zero
// length this is exactly the linear fixed–free chain of N = 9 equal masses. Its normal modes:
// shapes φ_j(r) ∝ sin(r·θ_j), θ_j = (2j − 1)π/(2N + 1), frequencies ω_j = 2√(k/m)·sin(θ_j/2),
// 3.693 to 44.13 rad/s, so h_j = ω_j·dt runs from 0.0616 to 0.7355 ("stiff": a tenth of a period
// per step for the fastest mode). Each scheme acts on each mode as on one oscillator
// (test_oscillator), so the one-oscillator closed forms, summed over the modes, give the rope's:
// the tests project the state on the modes and check them.

constexpr int kRopeFree = 9;
constexpr double kRopeK = 500.0, kRopeMass = 1.0;
constexpr std::int64_t kRopeRate = 60;

StructureSettings longitudinalRope() {
  StructureSettings s;
  s.name = "rope";
  RopeShape rope;
  rope.start = Eigen::Vector3d::Zero();
  rope.end = Eigen::Vector3d(2.0, 0.0, 0.0);
  rope.count = kRopeFree + 1;
  rope.pinStart = true;
  s.shape = rope;
  s.mass = kRopeMass;
  s.stiffness = kRopeK;
  s.velocity = Eigen::Vector3d(0.2, 0.0, 0.0);
  return s;
}

/// The rope's modes, and the state in their coordinates: for mode j, x_j = ω_j·q_j and v_j = q̇_j,
/// where q_j = Σ_r φ_j(r)·u_r (u_r: displacement along x of row r = 1 … N from where it was
/// built; φ_j orthonormal). Mode j's energy is ½m·(x_j² + v_j²), and they sum to the rope's.
struct RopeModes {
  std::vector<std::vector<double>> shape;  // [j][r − 1]
  std::vector<double> h;                   // ω_j·dt
  std::vector<double> rest;                // x of rows 1 … N as built
  std::vector<double> x, v;                // the state last projected

  RopeModes() {
    const double dt = floatDt(kRopeRate);
    for (int j = 1; j <= kRopeFree; ++j) {
      const double theta = (2.0 * j - 1.0) * kPi / (2.0 * kRopeFree + 1.0);
      std::vector<double> phi;
      double norm = 0.0;
      for (int r = 1; r <= kRopeFree; ++r) {
        phi.push_back(std::sin(r * theta));
        norm += phi.back() * phi.back();
      }
      for (double& f : phi) f /= std::sqrt(norm);
      shape.push_back(phi);
      h.push_back(2.0 * std::sqrt(kRopeK / kRopeMass) * std::sin(theta / 2.0) * dt);
    }
    const StructureBuild build = buildStructure(longitudinalRope(), kSeed, 0);
    for (int r = 1; r <= kRopeFree; ++r)
      rest.push_back(build.particles[static_cast<std::size_t>(r)].position.x());
    x.assign(kRopeFree, 0.0);
    v.assign(kRopeFree, 0.0);
    for (int j = 0; j < kRopeFree; ++j) {
      for (int r = 1; r <= kRopeFree; ++r)
        v[j] += shape[j][r - 1] * build.particles[static_cast<std::size_t>(r)].velocity.x();
    }
  }
  void project(const ParticlePool& pool) {
    const double dt = floatDt(kRopeRate);
    for (int j = 0; j < kRopeFree; ++j) {
      double q = 0.0, qdot = 0.0;
      for (int r = 1; r <= kRopeFree; ++r) {
        q += shape[j][r - 1] * (pool.position().x[r] - rest[r - 1]);
        qdot += shape[j][r - 1] * pool.velocity().x[r];
      }
      x[j] = h[j] / dt * q;
      v[j] = qdot;
    }
  }
  double energy(int j) const { return 0.5 * kRopeMass * (x[j] * x[j] + v[j] * v[j]); }
};

/// Runs the rope under `integrator`, calling `observe(n, energy)` after every tick n ≥ 1 with the
/// modes projected; stops after `ticks` or when `observe` returns false.
template <typename Observe>
void runRope(const std::string& integrator, std::int64_t ticks, RopeModes& modes, Observe observe) {
  ParticleSystem system(settingsFor(integrator, kRopeRate), {}, ForceSet{}, {longitudinalRope()});
  for (std::int64_t n = 1; n <= ticks; ++n) {
    system.step();
    if (n == 1) {
      ASSERT_EQ(system.pool().size(), 10u);
      ASSERT_NE(system.springs(), nullptr);
      ASSERT_EQ(system.springs()->springs().size(), 9u);
    }
    for (int r = 0; r <= kRopeFree; ++r) ASSERT_EQ(system.pool().position().y[r], 0.0f);
    modes.project(system.pool());
    if (!observe(n, energyOf(system.pool(), *system.springs()).total())) return;
  }
}

// Explicit Euler multiplies each mode's energy by exactly 1 + h_j² per step, so the rope's energy
// after n steps is Σ_j E0_j·(1 + h_j²)ⁿ. The run follows that to round-off for the first 30 ticks
// (measured: within 8e-5, energy 307·E0 at tick 30), until a spring is squeezed through zero length
// at tick 32 and the chain stops being linear. Nothing stops the growth after that either: every
// ten ticks end with more energy than the ten before, past 1e12·E0 within 2 s (measured: tick 90,
// 1.5 s).
TEST(RopeEnergy, ExplicitEulerMakesAStiffRopesEnergyGrowWithoutBound) {
  RopeModes modes;
  const double e0 = energyOf(buildStructure(longitudinalRope(), kSeed, 0)).total();
  ASSERT_NEAR(e0, 9 * 0.5 * 0.2f * 0.2f, 1e-12);
  std::vector<double> e0j;
  double sum = 0.0;
  for (int j = 0; j < kRopeFree; ++j) {
    e0j.push_back(modes.energy(j));
    sum += e0j.back();
  }
  // 1e-9: the springs start stretched by float rounding only (PE ~1e-12 J).
  ASSERT_NEAR(sum / e0, 1.0, 1e-9) << "the modes are orthonormal";
  std::vector<double> e{e0};
  runRope("explicit_euler", 2 * kRopeRate, modes, [&](std::int64_t n, double energy) {
    e.push_back(energy);
    if (n <= 30) {
      double model = 0.0;
      for (int j = 0; j < kRopeFree; ++j)
        model += e0j[j] * std::pow(1.0 + modes.h[j] * modes.h[j], n);
      // Each tick's rounding (4u of the energy) lands in every mode, the fastest of which then
      // grows by g = 1 + h_max² per tick: 4u·(gⁿ − 1)/(g − 1) after n ticks, capped at 2e-4.
      const double g = 1.0 + modes.h.back() * modes.h.back();
      const double tolerance = std::min(4.0 * kFloatU * (std::pow(g, n) - 1.0) / (g - 1.0), 2e-4);
      EXPECT_NEAR(energy / model, 1.0, tolerance) << "after " << n << " ticks";
    }
    return energy <= 1e12 * e0;
  });
  ASSERT_GT(e.back(), 1e12 * e0) << "after " << e.size() - 1 << " ticks";
  EXPECT_LE(e.size() - 1, 120u) << "ticks to pass 1e12·E0";
  // Never back: every ten ticks end with more energy than the ten before.
  for (std::size_t n = 10; n < e.size(); n += 10)
    EXPECT_GT(e[n], e[n - 10]) << "after " << n << " ticks";
}

// Semi-implicit Euler conserves Q_j = x_j² + v_j² − h_j·x_j·v_j on each mode, so the sum
// Σ ½m·Q_j stays at its initial E0 (every x_j starts at 0) to round-off, and each mode's energy
// stays in [Q_j/(2 + h_j), Q_j/(2 − h_j)]·m: the rope's, in [Σ 2·E0_j/(2 + h_j), Σ 2·E0_j/(2 −
// h_j)] = [0.95781, 1.05020]·E0, for all 60 s (3600 ticks). Measured: energy in
// [0.96120, 1.04610]·E0, Σ ½m·Q_j within 8.1e-5 of E0 (round-off allowance 8.6e-4).
TEST(RopeEnergy, SemiImplicitEulerKeepsAnUndampedRopesEnergyBoundedFor60s) {
  RopeModes modes;
  const double e0 = energyOf(buildStructure(longitudinalRope(), kSeed, 0)).total();
  double lo = 0.0, hi = 0.0;
  for (int j = 0; j < kRopeFree; ++j) {
    lo += 2.0 * modes.energy(j) / (2.0 + modes.h[j]);
    hi += 2.0 * modes.energy(j) / (2.0 - modes.h[j]);
  }
  double eMin = kInf, eMax = 0.0;
  std::int64_t ticks = 0;
  runRope("semi_implicit_euler", 60 * kRopeRate, modes, [&](std::int64_t n, double energy) {
    double q = 0.0;
    for (int j = 0; j < kRopeFree; ++j) {
      q += 0.5 * kRopeMass *
           (modes.x[j] * modes.x[j] + modes.v[j] * modes.v[j] -
            modes.h[j] * modes.x[j] * modes.v[j]);
    }
    EXPECT_NEAR(q / e0, 1.0, roundOff(n)) << "after " << n << " ticks";
    eMin = std::min(eMin, energy);
    eMax = std::max(eMax, energy);
    ticks = n;
    return true;
  });
  EXPECT_EQ(ticks, 60 * kRopeRate);
  const double slack = roundOff(ticks);
  EXPECT_GE(eMin / e0, lo / e0 * (1.0 - slack));
  EXPECT_LE(eMax / e0, hi / e0 * (1.0 + slack));
}

// Velocity Verlet conserves Q_j = (1 − h_j²/4)·x_j² + v_j² on each mode, so Σ ½m·Q_j stays at E0
// and the rope's energy in [E0, Σ E0_j/(1 − h_j²/4)] = [1, 1.00400]·E0, for all 60 s. Measured:
// energy in [1.00035, 1.00381]·E0, Σ ½m·Q_j within 4.1e-5 of E0.
TEST(RopeEnergy, VelocityVerletKeepsAnUndampedRopesEnergyBoundedFor60s) {
  RopeModes modes;
  const double e0 = energyOf(buildStructure(longitudinalRope(), kSeed, 0)).total();
  double hi = 0.0;
  for (int j = 0; j < kRopeFree; ++j) hi += modes.energy(j) / (1.0 - modes.h[j] * modes.h[j] / 4.0);
  double eMin = kInf, eMax = 0.0;
  std::int64_t ticks = 0;
  runRope("velocity_verlet", 60 * kRopeRate, modes, [&](std::int64_t n, double energy) {
    double q = 0.0;
    for (int j = 0; j < kRopeFree; ++j) {
      q += 0.5 * kRopeMass *
           ((1.0 - modes.h[j] * modes.h[j] / 4.0) * modes.x[j] * modes.x[j] +
            modes.v[j] * modes.v[j]);
    }
    EXPECT_NEAR(q / e0, 1.0, roundOff(n)) << "after " << n << " ticks";
    eMin = std::min(eMin, energy);
    eMax = std::max(eMax, energy);
    ticks = n;
    return true;
  });
  EXPECT_EQ(ticks, 60 * kRopeRate);
  const double slack = roundOff(ticks);
  EXPECT_GE(eMin / e0, 1.0 - slack);
  EXPECT_LE(eMax / e0, hi / e0 * (1.0 + slack));
}

// ---- a two-particle spring ---------------------------------------------------------------------
//
// Two free particles of mass m joined by one spring (k, c, rest L), started at rest stretched by A
// along a diagonal. Their separation obeys ẍ = −(2k/m)·x − (2c/m)·ẋ: it oscillates at
// ω = √(2k/m) and, damped, its amplitude decays as e^(−(c/m)·t).

struct PairCase {
  std::string integrator;
  std::int64_t rate;
};

void PrintTo(const PairCase& c, std::ostream* os) { *os << c.integrator << "@" << c.rate; }

/// |d| − L before tick 0 and after every tick, in double.
std::vector<double> pairExtension(const PairCase& c, double seconds, float k, float damping,
                                  float m) {
  constexpr float kRest = 1.0f;
  constexpr double kStretch = 0.1;
  ForceSet forces;
  SpringNetwork& network = addNetwork(forces);
  ParticleSystem system(settingsFor(c.integrator, c.rate), {}, std::move(forces));
  const Eigen::Vector3d u = Eigen::Vector3d(1.0, 2.0, 2.0) / 3.0;
  const Eigen::Vector3d centre(0.3, 1.0, -0.2);
  ParticlePool& pool = system.editPool();
  std::uint64_t ids[2];
  for (int i = 0; i < 2; ++i) {
    ParticleInit init;
    init.position = (centre + (i == 0 ? -0.5 : 0.5) * (kRest + kStretch) * u).cast<float>();
    init.mass = m;
    ids[i] = pool.id()[pool.spawn(init, 0)];
  }
  network.add(Spring{ids[0], ids[1], kRest, k, damping, 0.0f});
  auto extension = [&] { return (positionOf(pool, 1) - positionOf(pool, 0)).norm() - kRest; };
  std::vector<double> e{extension()};
  const auto ticks = std::llround(seconds * static_cast<double>(c.rate));
  for (std::int64_t n = 0; n < ticks; ++n) {
    system.step();
    e.push_back(extension());
  }
  return e;
}

/// Times of the zero crossings of `e` (sampled every dt), by linear interpolation.
std::vector<double> zeroCrossings(const std::vector<double>& e, double dt) {
  std::vector<double> t;
  for (std::size_t n = 0; n + 1 < e.size(); ++n) {
    if ((e[n] < 0.0) != (e[n + 1] < 0.0)) {
      t.push_back((static_cast<double>(n) + e[n] / (e[n] - e[n + 1])) * dt);
    }
  }
  return t;
}

class PairSpring : public ::testing::TestWithParam<PairCase> {};

// k = 100 N/m, m = 1 kg: ω = √200 = 14.142 rad/s, T = 0.44429 s; 10 s is 22.5 periods. The period
// is measured from the first to the last zero crossing. The requirement: within 1 % of 2π/√(2k/m).
// Sharper: each scheme's own discrete rotation per step θ gives T̃ = 2π·dt/θ (symplectic Euler and
// velocity Verlet: cos θ = 1 − h²/2, 1.4e-4 longer than T at 240 Hz; RK4: the phase of its step
// polynomial), and the measurement matches that to 1e-6. Measured: 0.4442240 s for both Eulers'
// map (−1.45e-4 from T; 3e-8 from T̃), 0.4442883 s for RK4 (1e-7 from T).
TEST_P(PairSpring, UndampedPairOscillatesAtRootTwoKOverM) {
  const PairCase& c = GetParam();
  const double k = 100.0, m = 1.0, dt = floatDt(c.rate);
  const std::vector<double> e = pairExtension(c, 10.0, 100.0f, 0.0f, 1.0f);
  const std::vector<double> t = zeroCrossings(e, dt);
  ASSERT_GE(t.size(), 40u);
  const double measured = 2.0 * (t.back() - t.front()) / static_cast<double>(t.size() - 1);
  const double omega = std::sqrt(2.0 * k / m), exact = 2.0 * kPi / omega;
  EXPECT_NEAR(measured / exact, 1.0, 0.01);
  const double h = omega * dt;
  const double theta = c.integrator == "rk4" ? std::atan2(h - h * h * h / 6.0,
                                                          1.0 - h * h / 2.0 + h * h * h * h / 24.0)
                                             : std::acos(1.0 - h * h / 2.0);
  EXPECT_NEAR(measured / (2.0 * kPi * dt / theta), 1.0, 1e-6)
      << "measured " << measured << " s, exact " << exact << " s";
  // Undamped: the amplitude stays 0.1 m (within the symplectic schemes' O(h) wobble).
  const auto [lo, hi] = std::minmax_element(e.begin(), e.end());
  EXPECT_NEAR(*hi, 0.1, 0.1 * h);
  EXPECT_NEAR(*lo, -0.1, 0.1 * h);
}

// c = 0.2 N·s/m: the envelope decays as e^(−0.2·t) (to 0.135 of A in 10 s). The rate is the
// least-squares slope of ln(peak) against time over every positive peak (each refined by a
// parabola through three samples, 22 of them); within 1 % of c/m. Measured: 0.20017 (semi-implicit
// Euler), 0.20035 (velocity Verlet), 0.19999 (RK4).
TEST_P(PairSpring, DampedPairDecaysAtCOverM) {
  const PairCase& c = GetParam();
  const double dt = floatDt(c.rate);
  const std::vector<double> e = pairExtension(c, 10.0, 100.0f, 0.2f, 1.0f);
  std::vector<double> tp, lp;
  for (std::size_t n = 1; n + 1 < e.size(); ++n) {
    if (e[n] > 0.0 && e[n] >= e[n - 1] && e[n] > e[n + 1]) {
      const double a = e[n - 1], b = e[n], d = e[n + 1];
      const double shift = 0.5 * (a - d) / (a - 2.0 * b + d);  // vertex offset, in steps
      tp.push_back((static_cast<double>(n) + shift) * dt);
      lp.push_back(std::log(b - 0.25 * (a - d) * shift));
    }
  }
  ASSERT_GE(tp.size(), 20u);
  double mt = 0.0, ml = 0.0;
  for (std::size_t i = 0; i < tp.size(); ++i) {
    mt += tp[i] / static_cast<double>(tp.size());
    ml += lp[i] / static_cast<double>(tp.size());
  }
  double num = 0.0, den = 0.0;
  for (std::size_t i = 0; i < tp.size(); ++i) {
    num += (tp[i] - mt) * (lp[i] - ml);
    den += (tp[i] - mt) * (tp[i] - mt);
  }
  const double rate = -num / den;
  EXPECT_NEAR(rate / 0.2, 1.0, 0.01) << "decay rate " << rate << " 1/s";
}

INSTANTIATE_TEST_SUITE_P(Schemes, PairSpring,
                         ::testing::Values(PairCase{"semi_implicit_euler", 240},
                                           PairCase{"velocity_verlet", 240}, PairCase{"rk4", 240}),
                         [](const ::testing::TestParamInfo<PairCase>& p) {
                           return p.param.integrator;
                         });

// ---- the gather: exactly opposite forces -------------------------------------------------------

// An isolated pair with equal masses, stretched, moving apart and sideways (so the damping term
// counts): the accelerations of the two ends are bitwise opposite, they are the same whether the
// rows are evaluated together or one by one, and they match the formula in double.
TEST(Gather, AnIsolatedPairGetsBitwiseOppositeAccelerations) {
  ParticlePool pool(8);
  ParticleInit a, b;
  a.position = Eigen::Vector3f(0.1f, -0.3f, 0.7f);
  a.velocity = Eigen::Vector3f(-0.4f, 0.2f, 0.05f);
  a.mass = 0.7f;
  b.position = Eigen::Vector3f(1.0f, 0.45f, 0.2f);
  b.velocity = Eigen::Vector3f(0.3f, -0.6f, 0.9f);
  b.mass = 0.7f;
  pool.spawn(a, 0);
  pool.spawn(b, 0);
  ForceSet forces;
  const Spring spring{0, 1, 0.8f, 37.0f, 0.3f, 0.0f};
  addNetwork(forces).add(spring);
  forces.beginTick(pool, 0);
  const ForceInput in{pool, Vec3View::of(pool.position()), Vec3View::of(pool.velocity()),
                      TickInstant{}};

  Vec3Column together, single;
  together.resize(2);
  single.resize(2);
  Vec3Rows all = Vec3Rows::of(together, RowRange{0, 2});
  forces.evaluate(in, RowRange{0, 2}, all);
  for (std::size_t r = 0; r < 2; ++r) {
    Vec3Rows one = Vec3Rows::of(single, RowRange{r, r + 1});
    forces.evaluate(in, RowRange{r, r + 1}, one);
  }
  const Eigen::Vector3d d = positionOf(pool, 1) - positionOf(pool, 0);
  const Eigen::Vector3d u = d.normalized();
  const double f =
      37.0 * (d.norm() - 0.8f) + 0.3f * (velocityOf(pool, 1) - velocityOf(pool, 0)).dot(u);
  const Eigen::Vector3d expected = f * u / static_cast<double>(0.7f);
  for (int c = 0; c < 3; ++c) {
    EXPECT_EQ(bitsOf(together[c][0]), bitsOf(-together[c][1])) << "component " << c;
    EXPECT_EQ(bitsOf(single[c][0]), bitsOf(together[c][0])) << "component " << c;
    EXPECT_EQ(bitsOf(single[c][1]), bitsOf(together[c][1])) << "component " << c;
    EXPECT_NEAR(together[c][0], expected[c], 1e-5 * expected.norm()) << "component " << c;
  }
  EXPECT_GT(expected.norm(), 1.0);
}

// ---- pinning -----------------------------------------------------------------------------------

class EveryScheme : public ::testing::TestWithParam<std::string> {};

// A rope pinned at both ends, its free particles thrown sideways, sags under gravity for 2 s: the
// pins keep their exact starting bits and zero velocity under every scheme, while the rest moves.
TEST_P(EveryScheme, PinnedParticlesDoNotMoveUnderGravityAndSprings) {
  StructureSettings s;
  RopeShape rope;
  rope.start = Eigen::Vector3d(-1.0, 2.0, 0.5);
  rope.end = Eigen::Vector3d(1.0, 2.0, 0.5);
  rope.count = 9;
  rope.pinStart = true;
  rope.pinEnd = true;
  s.shape = rope;
  s.mass = 0.1;
  s.stiffness = 50.0;
  s.damping = 0.1;
  s.velocity = Eigen::Vector3d(0.0, 0.0, 1.0);
  const StructureBuild build = buildStructure(s, kSeed, 0);
  ParticleSystem system(settingsFor(GetParam(), 120), {}, test::gravityOnly(), {s});
  system.stepTicks(240);
  const ParticlePool& pool = system.pool();
  ASSERT_EQ(pool.size(), 9u);
  int pins = 0;
  for (std::size_t r = 0; r < pool.size(); ++r) {
    ASSERT_EQ(pool.id()[r], r);
    const bool pin = std::isinf(build.particles[r].mass);
    EXPECT_EQ(pinned(pool, r), pin) << "row " << r;
    if (!pin) continue;
    ++pins;
    for (int c = 0; c < 3; ++c) {
      EXPECT_EQ(bitsOf(pool.position()[c][ix(r)]), bitsOf(build.particles[r].position[c]))
          << r << "," << c;
      EXPECT_EQ(pool.velocity()[c][ix(r)], 0.0f) << r << "," << c;
    }
  }
  EXPECT_EQ(pins, 2);
  // Something moved: explicit Euler, unstable here (ω·dt = 0.37 with little damping), moves the
  // most; the pins hold all the same.
  EXPECT_GT(std::abs(pool.position().y[4] - 2.0f), 0.05f) << "the middle moved";
}

INSTANTIATE_TEST_SUITE_P(All, EveryScheme, ::testing::ValuesIn(integratorNames()), integratorName);

// With gravity, drag and a spring on it, a pinned particle's acceleration is exactly zero.
TEST(Pinning, APinnedParticleGetsNoAccelerationFromAnyForce) {
  ParticlePool pool(4);
  ParticleInit pin, free;
  pin.mass = std::numeric_limits<float>::infinity();
  free.position = Eigen::Vector3f(0.0f, -1.5f, 0.0f);
  free.velocity = Eigen::Vector3f(1.0f, 0.0f, 0.0f);
  pool.spawn(pin, 0);
  pool.spawn(free, 0);
  EXPECT_EQ(inverseMassOf(pool.mass()[0]), 0.0f);
  ForceSet forces = test::gravityOnly();
  // The wind is oblique so that the pinned particle's drag is non-zero on every axis.
  forces.add(std::make_unique<LinearDrag>(0.5f, Eigen::Vector3f(3.0f, 1.0f, -2.0f)));
  addNetwork(forces).add(Spring{0, 1, 1.0f, 20.0f, 0.5f, 0.0f});
  forces.beginTick(pool, 0);
  Vec3Column a;
  a.resize(2);
  Vec3Rows rows = Vec3Rows::of(a, RowRange{0, 2});
  forces.evaluate(
      {pool, Vec3View::of(pool.position()), Vec3View::of(pool.velocity()), TickInstant{}},
      RowRange{0, 2}, rows);
  for (int c = 0; c < 3; ++c) EXPECT_EQ(bitsOf(a[c][0]), 0u) << "component " << c;
  // The free end: gravity, drag 0.5·((3, 1, −2) − (1, 0, 0)) = (1, 0.5, −1), and the spring
  // (stretch 0.5) pulling up 20·0.5/1 = 10. Float sums of these few terms are within 2 ulps.
  EXPECT_NEAR(a.x[1], 1.0f, 1e-6f);
  EXPECT_NEAR(a.y[1], -9.81f + 0.5f + 10.0f, 1e-5f);
  EXPECT_NEAR(a.z[1], -1.0f, 1e-6f);
}

// ---- a damped hanging chain settles to its static shape ----------------------------------------
//
// N = 10 particles of m = 0.05 kg, 0.1 m apart down from a pin at the origin, k = 50 N/m,
// c = 1.2 N·s/m, gravity 9.81 m/s², 120 Hz, 60 s. At rest, segment i counted from the bottom
// (i = 1 … 9) carries the i particles below it, so it is stretched by i·m·g/k (9.81 mm per
// particle): particle r (from the top) sits at y_r = −Σ_{s=1..r} (L + (N − s)·m·g/k), the bottom at
// −1.3415 m. The slowest mode (ω₁ = 5.22 rad/s) has damping ratio c·ω₁/(2k) = 0.063 and decays as
// e^(−0.33·t) (explicit Euler, which pumps ω²dt/2 back in, as e^(−0.22·t)): after 60 s, what is
// left of the initial 0.44 m is below 1e-6 m. (The damping cannot be much stronger: velocity Verlet
// feeds the damping a predicted velocity and is stable only while (4c/m)·dt < ~1.)
//
// What remains is float. Near 1.3 m positions are 1.2e-7 m apart (one ulp); a particle whose
// step v·dt is below half an ulp does not move at all, so the chain can stop a few ulps away from
// the exact float balance, with velocities up to ulp/(2·dt) = 7e-6 m/s that move nothing.
// Tolerance 1e-6 m (8 ulps at the bottom, 1e-4 of the smallest stretch); velocities below
// ulp/dt = 1.4e-5 m/s. Position Verlet is quantised harder (docs/integrators.md): a particle stays
// put while its |a|·dt² is below half an ulp, i.e. |a| < 8.6e-4 m/s², and such residual forces
// m·|a| on every particle, all one way, displace the bottom by 45·m·|a|/k = 3.9e-5 m: its
// tolerance, 4e-5 m. Measured worst errors: 1.8e-7 m (explicit and semi-implicit Euler), 1.0e-7
// (RK4), 7.1e-8 (midpoint, velocity Verlet), 1.4e-5 (position Verlet).

TEST_P(EveryScheme, ADampedHangingChainSettlesToTheAnalyticStaticShape) {
  constexpr int kN = 10;
  constexpr std::int64_t kRate = 120;
  StructureSettings s;
  RopeShape rope;
  rope.start = Eigen::Vector3d::Zero();
  rope.end = Eigen::Vector3d(0.0, -0.1 * (kN - 1), 0.0);
  rope.count = kN;
  rope.pinStart = true;
  s.shape = rope;
  s.mass = 0.05;
  s.stiffness = 50.0;
  s.damping = 1.2;
  ParticleSystem system(settingsFor(GetParam(), kRate), {}, test::gravityOnly(), {s});
  system.stepTicks(kRate * 60);
  const ParticlePool& pool = system.pool();
  ASSERT_EQ(pool.size(), static_cast<std::size_t>(kN));
  ASSERT_NE(system.springs(), nullptr);
  ASSERT_EQ(system.springs()->springs().size(), static_cast<std::size_t>(kN - 1));
  const Spring& spring = system.springs()->springs()[0];
  const double rest = spring.restLength, k = spring.stiffness, m = pool.mass()[1];
  EXPECT_NEAR(rest, 0.1, 1e-7);
  const double tolerance = GetParam() == "position_verlet" ? 4e-5 : 1e-6;
  const double ulp = std::nextafter(1.3415f, 2.0f) - 1.3415f;
  double y = 0.0, worst = 0.0;
  for (int r = 0; r < kN; ++r) {
    if (r > 0) y -= rest + (kN - r) * m * kG / k;
    const double error = std::abs(pool.position().y[r] - y);
    worst = std::max(worst, error);
    EXPECT_LT(error, tolerance) << "particle " << r << " at " << pool.position().y[r]
                                << ", analytic " << y;
    EXPECT_EQ(pool.position().x[r], 0.0f);
    EXPECT_EQ(pool.position().z[r], 0.0f);
    EXPECT_LT(velocityOf(pool, static_cast<std::size_t>(r)).norm(), ulp * kRate)
        << "particle " << r;
  }
  EXPECT_NEAR(y, -1.3415, 1e-4);  // the bottom, as a check on the sum itself
  EXPECT_EQ(bitsOf(pool.position().y[0]), bitsOf(0.0f)) << "the pin";
  RecordProperty("worst_error_m", std::to_string(worst));
}

// ---- a cloth pinned at two corners comes to rest ------------------------------------------------
//
// 10 × 10 particles 0.1 m apart in the vertical x–y plane, hanging from its two top corners under
// gravity; m = 0.05 kg, k = 50 N/m (shear 25, bend 5), c = 0.5 N·s/m on every spring; 240 Hz,
// 40 s. Gravity lies in the cloth's plane, so the motion stays in it (z = 0 exactly), and there
// every motion strains some spring: spring damping is the only loss, and enough. (Hung flat, the
// cloth would swing about the line through its pins, a rigid motion no spring damping can stop.)
// The cloth falls, sags and swings with up to ~10 J of kinetic energy, then stops. "At rest":
// below 1e-7 J, an rms speed over its 4.9 kg of √(2·KE/M) = 2e-4 m/s, 8 µm per frame at 24 fps.
// Measured after 40 s: 4.2e-9 J (explicit Euler, which pumps energy back in), 7.5e-10 (position
// Verlet), 1.4e-10 (midpoint), 2.5e-11 to 5.5e-11 (the others), from peaks of 9.7 to 10.2 J; the
// same order (6.0e-9 J at most) without the 9 stray springs of the cloth bug (see BuildStructure).
// Undamped, it still has several J after 40 s.

TEST_P(EveryScheme, AClothPinnedAtTwoCornersComesToRest) {
  constexpr std::int64_t kRate = 240;
  StructureSettings s;
  ClothShape cloth;
  cloth.width = 10;
  cloth.height = 10;
  cloth.spacing = 0.1;
  cloth.pins = ClothPins::TopCorners;
  s.shape = cloth;
  s.mass = 0.05;
  s.stiffness = 50.0;
  s.damping = 0.5;
  const StructureBuild build = buildStructure(s, kSeed, 0);
  ParticleSystem system(settingsFor(GetParam(), kRate), {}, test::gravityOnly(), {s});
  double peak = 0.0;
  for (std::int64_t n = 0; n < kRate * 40; ++n) {
    system.step();
    if (n % 8 == 0) peak = std::max(peak, energyOf(system.pool(), *system.springs(), kG).kinetic);
  }
  const double kinetic = energyOf(system.pool(), *system.springs(), kG).kinetic;
  const ParticlePool& pool = system.pool();
  ASSERT_EQ(pool.size(), 100u);
  int pins = 0;
  for (std::size_t r = 0; r < pool.size(); ++r) {
    if (!pinned(pool, r)) {
      EXPECT_EQ(pool.position().z[ix(r)], 0.0f);
      continue;
    }
    ++pins;
    for (int c = 0; c < 3; ++c) {
      EXPECT_EQ(bitsOf(pool.position()[c][ix(r)]), bitsOf(build.particles[r].position[c]))
          << "pin " << r;
      EXPECT_EQ(bitsOf(pool.velocity()[c][ix(r)]), 0u) << "pin " << r;
    }
  }
  EXPECT_EQ(pins, 2);
  EXPECT_GT(peak, 1.0) << "it did fall";
  EXPECT_LT(kinetic, 1e-7) << "peak " << peak << " J";
  RecordProperty("final_kinetic_J", std::to_string(kinetic));
}

// ---- deaths, late births, breaks ---------------------------------------------------------------

// `count` particles at tick 0, particle i at i·step, all immortal but particle `dies`, which lives
// 0.5 s.
void spawnInARow(ParticlePool& pool, int count, const Eigen::Vector3f& step, int dies) {
  for (int i = 0; i < count; ++i) {
    ParticleInit p;
    p.position = static_cast<float>(i) * step;
    p.lifetime = i == dies ? 0.5f : std::numeric_limits<float>::infinity();
    pool.spawn(p, 0);
  }
}

// Three particles in a row, springs 0–1 and 1–2, both stretched; particle 0 lives 0.5 s (30 ticks).
// Its spring is gone from the tick after it died, and from then on nothing pulls on the survivors
// from outside: their momentum (equal masses: v1 + v2) stays put, where before it did not.
TEST(SpringLifecycle, SpringsWhoseEndDiesAreRemoved) {
  ForceSet forces;
  SpringNetwork& network = addNetwork(forces);
  ParticleSystem system(settingsFor("semi_implicit_euler", 60), {}, std::move(forces));
  ParticlePool& pool = system.editPool();
  spawnInARow(pool, 3, Eigen::Vector3f(1.1f, 0.1f, 0.0f), 0);
  network.add(Spring{0, 1, 1.0f, 10.0f, 0.1f, 0.0f});
  network.add(Spring{1, 2, 1.0f, 10.0f, 0.1f, 0.0f});
  auto momentum = [&] {
    return (velocityOf(pool, pool.size() - 2) + velocityOf(pool, pool.size() - 1)).eval();
  };
  system.stepTicks(29);
  ASSERT_EQ(pool.size(), 3u);
  EXPECT_GT(momentum().norm(), 0.1) << "particle 0 pulls on the others";
  system.step();
  ASSERT_EQ(pool.size(), 2u) << "particle 0 died after 30 ticks";
  ASSERT_EQ(pool.id()[0], 1u);
  const Eigen::Vector3d p0 = momentum();
  system.step();
  ASSERT_EQ(network.springs().size(), 1u);
  EXPECT_EQ(network.springs()[0].a, 1u);
  EXPECT_EQ(network.springs()[0].b, 2u);
  EXPECT_EQ(network.brokenCount(), 0u) << "a death is not a break";
  system.stepTicks(120);
  EXPECT_LT((momentum() - p0).norm(), 1e-5)
      << "momentum " << momentum().transpose() << " was " << p0.transpose();
  const Eigen::Vector3d d = positionOf(pool, 1) - positionOf(pool, 0);
  EXPECT_LT(d.norm(), 1.2) << "the 1–2 spring still acts";
}

// A structure born into a pool with room for only part of it keeps the springs between the
// particles that were born and no other: a spring to a refused particle has no end to pull.
TEST(SpringLifecycle, AStructureCutShortByAFullPoolKeepsOnlyTheSpringsOfItsBornParticles) {
  StructureSettings s;
  RopeShape rope;
  rope.start = Eigen::Vector3d(0.0, 1.0, 0.0);
  rope.end = Eigen::Vector3d(0.5, 0.0, 0.25);
  rope.count = 9;
  s.shape = rope;
  SystemSettings settings = settingsFor("semi_implicit_euler", 60);
  settings.maxParticles = 5;
  ParticleSystem system(settings, {}, test::gravityOnly(), {s});
  system.step();
  ASSERT_EQ(system.pool().size(), 5u);
  EXPECT_EQ(system.pool().droppedSpawns(), 4u);
  ASSERT_NE(system.springs(), nullptr);
  const std::vector<Spring>& springs = system.springs()->springs();
  ASSERT_EQ(springs.size(), 4u) << "0–1, 1–2, 2–3, 3–4 of the rope's 8";
  for (std::size_t i = 0; i < springs.size(); ++i) {
    EXPECT_EQ(springs[i].a, i);
    EXPECT_EQ(springs[i].b, i + 1);
  }
}

// When a particle in the middle of the rows dies, the rows after it are no longer their ids minus
// the first id: a spring between two of them is found by search, kept, and still pulls.
TEST(SpringLifecycle, SpringsPastADeadRowKeepTheirEnds) {
  ForceSet forces;
  SpringNetwork& network = addNetwork(forces);
  ParticleSystem system(settingsFor("semi_implicit_euler", 60), {}, std::move(forces));
  ParticlePool& pool = system.editPool();
  spawnInARow(pool, 4, Eigen::Vector3f(1.5f, 0.0f, 0.0f), 1);
  network.add(Spring{0, 1, 1.0f, 10.0f, 0.0f, 0.0f});
  network.add(Spring{2, 3, 1.0f, 10.0f, 0.0f, 0.0f});
  system.stepTicks(31);  // particle 1 dies after tick 30
  ASSERT_EQ(pool.size(), 3u);
  ASSERT_EQ(pool.id()[1], 2u);
  ASSERT_EQ(network.springs().size(), 1u);
  EXPECT_EQ(network.springs()[0].a, 2u);
  EXPECT_EQ(network.springs()[0].b, 3u);
  // Stretched by 0.5 m at the start, the pair has moved together since, as one spring does.
  EXPECT_LT(pool.position().x[2] - pool.position().x[1], 1.5f);
  EXPECT_EQ(bitsOf(pool.velocity().x[1]), bitsOf(-pool.velocity().x[2]));
}

// A spring to a particle not born yet does nothing; once it is born, it pulls.
TEST(SpringLifecycle, ASpringWaitsForItsEndsToBeBorn) {
  ForceSet forces;
  SpringNetwork& network = addNetwork(forces);
  ParticleSystem system(settingsFor("semi_implicit_euler", 60), {}, std::move(forces));
  ParticlePool& pool = system.editPool();
  pool.spawn(ParticleInit{}, 0);
  network.add(Spring{0, 1, 1.0f, 10.0f, 0.0f, 0.0f});
  system.stepTicks(10);
  EXPECT_EQ(velocityOf(pool, 0), Eigen::Vector3d::Zero());
  EXPECT_EQ(network.springs().size(), 1u) << "not born is not dead";
  ParticleInit late;
  late.position = Eigen::Vector3f(2.0f, 0.0f, 0.0f);
  pool.spawn(late, system.tickCount());
  system.step();
  EXPECT_GT(pool.velocity().x[0], 0.0f) << "pulled toward the new particle";
  EXPECT_EQ(bitsOf(pool.velocity().x[0]), bitsOf(-pool.velocity().x[1]));
}

// Two unit masses fly apart at 2 m/s each on a k = 1 N/m spring that would turn them back at a
// stretch of 4/√2 = 2.8 m; its break ratio 1.5 (L = 1) stops that. The network checks the length
// at the start of each tick: the spring is there for every tick that starts at or below 1.5 m and
// gone (counted once) from the first that starts above it; after that the velocities never change.
TEST(SpringLifecycle, ASpringBreaksAtTheFirstTickThatStartsStretchedPastItsRatio) {
  ForceSet forces;
  SpringNetwork& network = addNetwork(forces);
  ParticleSystem system(settingsFor("semi_implicit_euler", 60), {}, std::move(forces));
  ParticlePool& pool = system.editPool();
  for (int i = 0; i < 2; ++i) {
    ParticleInit p;
    p.position = Eigen::Vector3f(i == 0 ? -0.5f : 0.5f, 0.0f, 0.0f);
    p.velocity = Eigen::Vector3f(i == 0 ? -2.0f : 2.0f, 0.0f, 0.0f);
    pool.spawn(p, 0);
  }
  network.add(Spring{0, 1, 1.0f, 1.0f, 0.0f, 1.5f});
  network.add(Spring{0, 1, 10.0f, 0.0f, 0.0f, 0.0f});  // slack, k = 0, never breaks
  int brokeAt = -1;
  for (int n = 0; n < 60; ++n) {
    const double length = (positionOf(pool, 1) - positionOf(pool, 0)).norm();
    const Eigen::Vector3d v0 = velocityOf(pool, 0);
    system.step();
    if (length > 1.5) {
      if (brokeAt < 0) brokeAt = n;
      EXPECT_EQ(network.brokenCount(), 1u) << "tick " << n << " started at " << length << " m";
      EXPECT_EQ(network.springs().size(), 1u) << "tick " << n;
      EXPECT_EQ(velocityOf(pool, 0), v0) << "tick " << n << ": no spring, no force";
    } else {
      EXPECT_EQ(network.brokenCount(), 0u) << "tick " << n << " started at " << length << " m";
      EXPECT_EQ(network.springs().size(), 2u) << "tick " << n;
    }
  }
  EXPECT_GT(brokeAt, 5) << "it broke (at tick " << brokeAt << ")";
  ASSERT_EQ(network.springs().size(), 1u);
  EXPECT_EQ(network.springs()[0].breakRatio, 0.0f) << "the one that never breaks stays";
}

// A spring already stretched past its ratio breaks at the very first tick; one with a larger
// ratio, or none, does not.
TEST(SpringLifecycle, OnlySpringsStretchedPastTheirRatioBreak) {
  ForceSet forces;
  SpringNetwork& network = addNetwork(forces);
  ParticleSystem system(settingsFor("semi_implicit_euler", 60), {}, std::move(forces));
  ParticlePool& pool = system.editPool();
  for (float x : {0.0f, 2.0f, 4.0f, 6.0f}) {
    ParticleInit p;
    p.position = Eigen::Vector3f(x, 0.0f, 0.0f);
    pool.spawn(p, 0);
  }
  network.add(Spring{0, 1, 1.0f, 5.0f, 0.0f, 1.9f});  // 2 > 1.9: breaks
  network.add(Spring{1, 2, 1.0f, 5.0f, 0.0f, 2.1f});  // 2 < 2.1: holds
  network.add(Spring{2, 3, 1.0f, 5.0f, 0.0f, 0.0f});  // never breaks
  system.step();
  EXPECT_EQ(network.brokenCount(), 1u);
  ASSERT_EQ(network.springs().size(), 2u);
  EXPECT_EQ(network.springs()[0].a, 1u);
  EXPECT_EQ(network.springs()[1].a, 2u);
  EXPECT_EQ(pool.velocity().x[0], 0.0f) << "particle 0 has no spring left";
  EXPECT_GT(pool.velocity().x[1], 0.0f) << "particle 1 is pulled by 1–2 only";
}

// Regression (issue 10, item 16), the documented caveat: velocity Verlet keeps a(t) from the end of
// the last tick, so a spring that breaks at the start of a tick still pulls in that tick's first
// half-kick, by exactly h/2 times its last acceleration. Semi-implicit Euler, which evaluates
// forces within the tick, sees no spring at all in that tick.
TEST(SpringLifecycle, VelocityVerletsKeptAccelerationIncludesASpringThatBrokeAtTheTicksStart) {
  constexpr std::int64_t kRate = 60;
  const double h = floatDt(kRate);
  for (const std::string integrator : {"velocity_verlet", "semi_implicit_euler"}) {
    ForceSet forces;
    SpringNetwork& network = addNetwork(forces);
    ParticleSystem system(settingsFor(integrator, kRate), {}, std::move(forces));
    ParticlePool& pool = system.editPool();
    // 2 m apart and flying apart at 20 m/s: whole at the first tick's start (2 < 2.1), broken at
    // the second's (2.33 > 2.1).
    for (float side : {-1.0f, 1.0f}) {
      ParticleInit p;
      p.position = Eigen::Vector3f(side, 0.0f, 0.0f);
      p.velocity = Eigen::Vector3f(10.0f * side, 0.0f, 0.0f);
      pool.spawn(p, 0);
    }
    constexpr double kStiffness = 5.0, kRest = 1.0;
    network.add(
        Spring{0, 1, static_cast<float>(kRest), static_cast<float>(kStiffness), 0.0f, 2.1f});
    system.step();
    ASSERT_EQ(network.brokenCount(), 0u) << integrator;
    const double length = positionOf(pool, 1).x() - positionOf(pool, 0).x();
    const Eigen::Vector3d v1 = velocityOf(pool, 0);
    system.step();
    ASSERT_EQ(network.brokenCount(), 1u) << integrator;
    const double dv = velocityOf(pool, 0).x() - v1.x();
    if (integrator == "velocity_verlet") {
      // Particle 0's last acceleration: k·(L − rest)/m toward particle 1, at the length the first
      // tick ended with (5.5e-2 m/s here).
      const double halfKick = h / 2.0 * kStiffness * (length - kRest);
      EXPECT_NEAR(dv, halfKick, 8.0 * kFloatU * std::abs(v1.x())) << "length " << length;
      EXPECT_GT(dv, 0.05);
    } else {
      EXPECT_EQ(dv, 0.0) << "no spring, no force in the tick it broke";
    }
  }
}

// ---- the bits do not depend on the thread count ------------------------------------------------
//
// A 100 × 100 cloth (10 000 rows: two blocks of kParallelBlockRows, springs across the boundary)
// falling flat under gravity from its two top corners, springs breaking near the corners as it
// does: the state hash after every tick, the springs left and the break count are the same for 1,
// 2 and 3 threads.

class ClothThreads : public ::testing::TestWithParam<std::string> {};

TEST_P(ClothThreads, OneTwoAndThreeThreadsGiveTheSameHashAfterEveryTick) {
  static_assert(kParallelBlockRows < 100 * 100);
  StructureSettings s;
  ClothShape cloth;
  cloth.origin = Eigen::Vector3d(-1.0, 1.0, -1.0);
  cloth.axisU = Eigen::Vector3d::UnitX();
  cloth.axisV = Eigen::Vector3d::UnitZ();  // horizontal
  cloth.width = 100;
  cloth.height = 100;
  cloth.spacing = 0.02;
  cloth.pins = ClothPins::TopCorners;
  s.shape = cloth;
  s.mass = 0.01;
  s.stiffness = 5.0;
  s.damping = 0.02;
  s.breakRatio = 1.5;
  s.velocity = Eigen::Vector3d(0.1, 0.0, -0.05);
  std::vector<std::vector<std::uint64_t>> hashes;
  std::vector<std::vector<Spring>> left;
  std::vector<std::uint64_t> broken;
  for (int threads : {1, 2, 3}) {
    ParticleSystem system(settingsFor(GetParam(), 60, threads), {}, test::gravityOnly(), {s});
    std::vector<std::uint64_t> trace;
    system.setTickObserver(
        [&](const ParticleSystem& sys) { trace.push_back(stateHash(sys.pool())); });
    system.stepTicks(45);
    hashes.push_back(trace);
    left.push_back(system.springs()->springs());
    broken.push_back(system.springs()->brokenCount());
  }
  EXPECT_GT(broken[0], 0u) << "the run should exercise breaking";
  for (std::size_t i = 1; i < hashes.size(); ++i) {
    EXPECT_EQ(hashes[i], hashes[0]) << i + 1 << " threads";
    EXPECT_EQ(broken[i], broken[0]) << i + 1 << " threads";
    ASSERT_EQ(left[i].size(), left[0].size()) << i + 1 << " threads";
    for (std::size_t j = 0; j < left[0].size(); ++j) {
      ASSERT_EQ(left[i][j].a, left[0][j].a);
      ASSERT_EQ(left[i][j].b, left[0][j].b);
    }
  }
  RecordProperty("broken", std::to_string(broken[0]));
  RecordProperty("final_hash", hashToHex(hashes[0].back()));
}

INSTANTIATE_TEST_SUITE_P(Schemes, ClothThreads,
                         ::testing::Values("semi_implicit_euler", "velocity_verlet", "rk4"),
                         integratorName);

// A network keeps its tables from the tick before when no row moved, no end was born or died and
// no spring broke. Tick by tick, through births, deaths and breaks, its springs and forces are
// those of a network that rebuilds everything (a fresh one restored from its springs).
TEST(SpringTables, KeptFromTheTickBeforeTheyGiveTheForcesOfARebuild) {
  ParticlePool pool(64);
  for (int i = 0; i < 40; ++i) {
    ParticleInit init;
    init.position = Eigen::Vector3f(static_cast<float>(i) * 1.1f, 0.01f * static_cast<float>(i), 0);
    init.velocity = Eigen::Vector3f(0, 0.1f * static_cast<float>(i % 3), 0);
    init.mass = i == 0 ? std::numeric_limits<float>::infinity() : 1.0f;
    pool.spawn(init, 0);
  }
  SpringNetwork live;
  for (std::uint64_t i = 0; i + 1 < 40; ++i)
    live.add(Spring{i, i + 1, 1.0f, 40.0f, 0.5f, i % 4 == 0 ? 1.5f : 0.0f});
  for (std::uint64_t i = 40; i < 45; ++i) live.add(Spring{i - 30, i, 1.0f, 20.0f, 0.0f, 0.0f});
  for (std::int64_t tick = 0; tick < 30; ++tick) {
    if (tick == 5) {
      for (int i = 40; i < 45; ++i) pool.spawn(ParticleInit{}, tick);  // pending ends born
    }
    if (tick == 10) {
      pool.dead()[7] = 1;  // an end dies
      pool.removeDead();
    }
    if (tick == 15) pool.position().x[20] += 5.0f;  // stretches springs 19-20 and 20-21
    if (tick == 20) pool.position().x[32] += 0.2f;  // moves, breaks nothing
    SpringNetwork fresh;
    fresh.restore(live.springs(), live.brokenCount());
    live.beginTick(pool, tick);
    fresh.beginTick(pool, tick);
    ASSERT_EQ(live.springs().size(), fresh.springs().size()) << "tick " << tick;
    for (std::size_t k = 0; k < live.springs().size(); ++k) {
      ASSERT_EQ(live.springs()[k].a, fresh.springs()[k].a) << "tick " << tick;
      ASSERT_EQ(live.springs()[k].b, fresh.springs()[k].b) << "tick " << tick;
    }
    ASSERT_EQ(live.brokenCount(), fresh.brokenCount()) << "tick " << tick;
    const ForceInput in{pool, Vec3View::of(pool.position()), Vec3View::of(pool.velocity()), {}};
    const RowRange rows{0, pool.size()};
    Vec3Column a, b;
    a.resize(ix(pool.size()));
    b.resize(ix(pool.size()));
    for (int c = 0; c < 3; ++c) {
      a[c].setZero();
      b[c].setZero();
    }
    Vec3Rows ra = Vec3Rows::of(a, rows), rb = Vec3Rows::of(b, rows);
    live.accumulate(in, rows, ra);
    fresh.accumulate(in, rows, rb);
    for (std::size_t r = 0; r < pool.size(); ++r) {
      for (int c = 0; c < 3; ++c)
        ASSERT_EQ(bitsOf(a[c][ix(r)]), bitsOf(b[c][ix(r)])) << "tick " << tick << ", row " << r;
    }
    // Move every particle a little, as a tick would, so the break test sees new lengths.
    for (std::size_t r = 1; r < pool.size(); ++r) pool.position().y[ix(r)] += 0.001f * a.y[ix(r)];
  }
  EXPECT_EQ(live.brokenCount(), 1u);  // 20-21, breakable, pulled at tick 15 (19-20 cannot break)
}

}  // namespace
}  // namespace tickfx
