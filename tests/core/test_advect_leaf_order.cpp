// Advection visiting rows leaf by leaf (integrators/LeafOrder, Advection::Visits::LeafOrder)
// against the row-order reference: the same bits in every column, for every scheme, on
// scattered and coherent rows, on 1, 2 and 3 threads, while particles cross leaves, are born and
// die between ticks. And LeafOrder itself: a stable sort by grid block, or no order where the
// rows are coherent already.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include "Sanitized.h"
#include "fields/ForceSet.h"
#include "fields/vdb/AnalyticField.h"
#include "fields/vdb/VectorField.h"
#include "integrators/Advection.h"
#include "integrators/Integrator.h"
#include "integrators/LeafOrder.h"
#include "particles/ParticlePool.h"

namespace tickfx {
namespace {

using Visits = Advection::Visits;

constexpr AdvectionScheme kSchemes[] = {AdvectionScheme::Euler, AdvectionScheme::Midpoint,
                                        AdvectionScheme::Heun, AdvectionScheme::RungeKutta4};
constexpr std::int64_t kRate = 24;
// The thread counts each scheme's leaf order is checked on: one (the serial path), two and three
// (blocks split unevenly). A sanitizer build runs one and three (test::kSanitized).
const std::vector<int> kThreadCounts =
    test::kSanitized ? std::vector<int>{1, 3} : std::vector<int>{1, 2, 3};

// Point i of a Weyl sequence in [-half, half]³: consecutive points far apart.
Eigen::Vector3f weyl(std::size_t i, float half) {
  const double a[3] = {0.7548776662466927, 0.5698402909980532, 0.3611333928711215};
  Eigen::Vector3f p;
  for (int c = 0; c < 3; ++c) {
    p[c] = static_cast<float>(half * (2.0 * std::fmod(0.5 + a[c] * double(i + 1), 1.0) - 1.0));
  }
  return p;
}

// The leaf (8 voxels of 5 cm) a position lies in, as the fields below place it.
std::tuple<int, int, int> leafOf(const Eigen::Vector3f& p) {
  // World to index as the grid's map does it: x·(1/h) in double.
  const auto leaf = [](float x) {
    return static_cast<int>(std::floor(static_cast<double>(x) * (1.0 / 0.05))) >> 3;
  };
  return {leaf(p.x()), leaf(p.y()), leaf(p.z())};
}

// `n` points, scattered (sequence order) or coherent (sorted by leaf, as the bench's are).
std::vector<Eigen::Vector3f> points(std::size_t n, bool coherent, std::size_t first = 0) {
  std::vector<Eigen::Vector3f> p;
  for (std::size_t i = 0; i < n; ++i) p.push_back(weyl(first + i, 1.2f));
  if (coherent) {
    std::stable_sort(p.begin(), p.end(), [](const auto& a, const auto& b) {
      return std::make_tuple(std::get<2>(leafOf(a)), std::get<1>(leafOf(a)),
                             std::get<0>(leafOf(a))) < std::make_tuple(std::get<2>(leafOf(b)),
                                                                       std::get<1>(leafOf(b)),
                                                                       std::get<0>(leafOf(b)));
    });
  }
  return p;
}

void spawnAll(ParticlePool& pool, const std::vector<Eigen::Vector3f>& at, std::int64_t tick) {
  for (const Eigen::Vector3f& x : at) {
    ParticleInit init;
    init.position = x;
    init.velocity = Eigen::Vector3f(3.0f, 2.0f, 1.0f);  // overwritten by the flow
    pool.spawn(init, tick);
  }
}

// The same `n` scattered points, stepped once, in each of two pools that keep the previous
// position.
void fillTwins(ParticlePool& a, ParticlePool& b, std::size_t n) {
  for (ParticlePool* pool : {&a, &b}) {
    pool->keepPrevious();
    spawnAll(*pool, points(n, false), 0);
    pool->markAllStepped();
  }
}

BakeSettings bakeBox(double half) {
  BakeSettings b;
  b.voxelSize = 0.05;
  b.min = Eigen::Vector3d::Constant(-half);
  b.max = Eigen::Vector3d::Constant(half);
  return b;
}

// Curl noise (|u| about 1 m/s) at 5 cm: one grid over all the points, or a sequence of three
// frames (blended between ticks) over a smaller box with the kill policy, so that particles
// outside sample zero and die at the tick's end.
ForceSet curlNoiseField(bool sequenceWithKill) {
  const AnalyticField noise = AnalyticField::curlNoise(5, 3.0, 1.0, 4, 2.0);
  VectorField::Settings s;
  s.file = "baked";
  s.mode = VectorField::Mode::Advect;
  ForceSet forces;
  if (!sequenceWithKill) {
    forces.add(bakeVectorField(noise, bakeBox(1.6), s));
    return forces;
  }
  s.outside = VectorField::Outside::Kill;
  s.fps = 10.0;
  s.firstFrame = 0;
  s.lastFrame = 2;
  forces.add(bakeVectorField(noise, bakeBox(1.0), s));
  return forces;
}

// Bit for bit: every row of the three columns a step writes (the previous position where the
// pools keep it; where they do not, it has no rows in either).
void expectSameBits(const ParticlePool& a, const ParticlePool& b, const std::string& what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  ASSERT_TRUE(std::equal(a.id().begin(), a.id().begin() + a.size(), b.id().begin())) << what;
  ASSERT_EQ(a.keepsPrevious(), b.keepsPrevious()) << what;
  const std::size_t n = a.size();
  const std::pair<const Vec3Column*, const Vec3Column*> columns[] = {
      {&a.position(), &b.position()},
      {&a.velocity(), &b.velocity()},
      {&a.previousPosition(), &b.previousPosition()}};
  const char* names[] = {"position", "velocity", "previous position"};
  if (!a.keepsPrevious()) {
    EXPECT_EQ(a.previousPosition().x.size(), 0) << what;
    EXPECT_EQ(b.previousPosition().x.size(), 0) << what;
  }
  const int kept = a.keepsPrevious() ? 3 : 2;
  for (int k = 0; k < kept; ++k) {
    for (int c = 0; c < 3; ++c) {
      const float* x = (*columns[k].first)[c].data();
      const float* y = (*columns[k].second)[c].data();
      if (std::memcmp(x, y, n * sizeof(float)) == 0) continue;
      std::size_t row = 0;
      while (std::memcmp(x + row, y + row, sizeof(float)) == 0) ++row;
      FAIL() << what << ": " << names[k] << "[" << c << "] of row " << row << " is " << x[row]
             << " against " << y[row];
    }
  }
}

// Between ticks, the same on both pools: every 7th particle by id dies, 600 are born.
void birthsAndDeaths(ParticlePool& pool, std::int64_t tick) {
  for (std::size_t r = 0; r < pool.size(); ++r) {
    if (pool.id()[r] % 7 == static_cast<std::uint64_t>(tick % 7)) pool.dead()[r] = 1;
  }
  pool.removeDead();
  spawnAll(pool, points(600, false, 100'000 + 1000 * static_cast<std::size_t>(tick)), tick);
  pool.markAllStepped();
}

// The number of particles whose leaf differs between `before` and the pool's positions now.
std::size_t leafChanges(const std::vector<Eigen::Vector3f>& before, const ParticlePool& pool) {
  std::size_t changed = 0;
  for (std::size_t r = 0; r < before.size(); ++r) {
    const Eigen::Vector3f now(pool.position().x[r], pool.position().y[r], pool.position().z[r]);
    changed += static_cast<std::size_t>(leafOf(now) != leafOf(before[r]));
  }
  return changed;
}

std::vector<Eigen::Vector3f> positionsOf(const ParticlePool& pool) {
  std::vector<Eigen::Vector3f> p;
  for (std::size_t r = 0; r < pool.size(); ++r) {
    p.emplace_back(pool.position().x[r], pool.position().y[r], pool.position().z[r]);
  }
  return p;
}

// ---- leaf order against row order --------------------------------------------------------------

// 20 000 particles (three blocks of rows), four ticks with births and deaths between them, a
// pinned particle among them: the leaf-ordered step on `threads` threads against the row-order
// step on one, column by column after every tick. `keepPrevious`: the pools keep the previous
// position and every tick writes it (a frame interpolating across each tick); else no tick does.
void expectLeafOrderMatchesRowOrder(AdvectionScheme scheme, bool coherent, int threads,
                                    bool sequenceWithKill, bool keepPrevious = true) {
  const std::string what =
      std::string(advectionSchemeName(scheme)) + (coherent ? ", coherent" : ", scattered") + ", " +
      std::to_string(threads) + " thread(s)" + (sequenceWithKill ? ", sequence with kill" : "") +
      (keepPrevious ? "" : ", no previous position");
  ForceSet forces = curlNoiseField(sequenceWithKill);
  ASSERT_TRUE(forces.gathersVelocity()) << what;
  ParticlePool reference(40'000), leafOrdered(40'000);
  const std::uint64_t pinned = 123;  // held still in both paths; 123 % 7 = 4: never killed below
  for (ParticlePool* pool : {&reference, &leafOrdered}) {
    if (keepPrevious) pool->keepPrevious();
    spawnAll(*pool, points(20'000, coherent), 0);
    pool->mass()[pinned] = std::numeric_limits<float>::infinity();
    pool->markAllStepped();
  }
  const Eigen::Vector3f pinnedAt = positionsOf(leafOrdered)[pinned];
  Advection rows(scheme, Visits::RowOrder), leaves(scheme, Visits::LeafOrder);
  tbb::task_arena one(1), many(threads);
  std::size_t crossed = 0, deaths = 0;
  for (std::int64_t k = 0; k < 4; ++k) {
    const StepTime time{k, kRate};
    const std::vector<Eigen::Vector3f> before = positionsOf(reference);
    forces.beginTick(reference, k);
    one.execute(
        [&] { rows.step(reference, forces, time, StepRows::wholePool(reference, keepPrevious)); });
    forces.beginTick(leafOrdered, k);
    many.execute([&] {
      leaves.step(leafOrdered, forces, time, StepRows::wholePool(leafOrdered, keepPrevious));
    });
    expectSameBits(reference, leafOrdered, what + ", tick " + std::to_string(k));
    crossed += leafChanges(before, reference);
    for (ParticlePool* pool : {&reference, &leafOrdered}) {
      forces.endTick(*pool, time.stage(2));
      const std::size_t alive = pool->size();
      birthsAndDeaths(*pool, k);
      if (pool == &reference) deaths += alive + 600 - pool->size();
    }
    expectSameBits(reference, leafOrdered, what + ", after births and deaths " + std::to_string(k));
  }
  // The order had to follow particles into other leaves, and rows to shift under it.
  EXPECT_GT(crossed, 2000u) << what;
  EXPECT_GT(deaths, 4u * 2000u) << what;
  const auto ids = leafOrdered.id().begin();
  const auto idsEnd = ids + leafOrdered.size();
  const auto row = std::find(ids, idsEnd, pinned);
  if (sequenceWithKill && row == idsEnd) return;  // killed outside the box
  ASSERT_NE(row, idsEnd) << what;
  const std::size_t r = static_cast<std::size_t>(row - leafOrdered.id().begin());
  EXPECT_LT(r, pinned) << what << ": rows ahead of it died";
  EXPECT_EQ(positionsOf(leafOrdered)[r], pinnedAt) << what;
  EXPECT_EQ(leafOrdered.velocity().x[static_cast<Eigen::Index>(r)], 0.0f) << what;
}

TEST(LeafOrderedAdvection, MatchesRowOrderBitForBitOnScatteredRows) {
  for (const AdvectionScheme scheme : kSchemes) {
    for (const int threads : kThreadCounts)
      expectLeafOrderMatchesRowOrder(scheme, false, threads, false);
  }
}

TEST(LeafOrderedAdvection, MatchesRowOrderBitForBitOnCoherentRows) {
  for (const AdvectionScheme scheme : kSchemes) {
    for (const int threads : kThreadCounts)
      expectLeafOrderMatchesRowOrder(scheme, true, threads, false);
  }
}

TEST(LeafOrderedAdvection, MatchesRowOrderBitForBitThroughASequenceWithKill) {
  for (const AdvectionScheme scheme : kSchemes) {
    for (const bool coherent : {false, true}) {
      expectLeafOrderMatchesRowOrder(scheme, coherent, 2, true);
    }
  }
}

TEST(LeafOrderedAdvection, WritesThePreviousPositionOnlyWhereRowOrderDoes) {
  // Ticks no frame interpolates across (StepRows::keepPrevious false) write no previous
  // position, in leaf order as in row order: the pools never get the column.
  for (const AdvectionScheme scheme : kSchemes) {
    for (const bool coherent : {false, true}) {
      expectLeafOrderMatchesRowOrder(scheme, coherent, 2, false, /*keepPrevious=*/false);
    }
  }
  // A pool whose previous position is state (position Verlet's, kept as such) has it written
  // by every tick, StepRows::keepPrevious or not.
  ForceSet forces = curlNoiseField(false);
  for (const AdvectionScheme scheme : kSchemes) {
    ParticlePool reference(20'000), leafOrdered(20'000);
    for (ParticlePool* pool : {&reference, &leafOrdered}) {
      pool->keepPrevious(/*asState=*/true);
      spawnAll(*pool, points(20'000, false), 0);
      pool->markAllStepped();
    }
    const std::vector<Eigen::Vector3f> start = positionsOf(leafOrdered);
    Advection rows(scheme, Visits::RowOrder), leaves(scheme, Visits::LeafOrder);
    tbb::task_arena two(2);
    rows.step(reference, forces, StepTime{0, kRate}, StepRows::wholePool(reference, false));
    two.execute([&] {
      leaves.step(leafOrdered, forces, StepTime{0, kRate}, StepRows::wholePool(leafOrdered, false));
    });
    expectSameBits(reference, leafOrdered, std::string(advectionSchemeName(scheme)));
    for (std::size_t r = 0; r < start.size(); r += 997) {
      const auto i = static_cast<Eigen::Index>(r);
      EXPECT_EQ(leafOrdered.previousPosition().x[i], start[r].x()) << r;
    }
  }
}

TEST(LeafOrderedAdvection, WritesTheStartsWhereACallerAsks) {
  // A block stepped with StepRows::starts (a block's collisions read them next) writes each row's
  // starting position there, at row − the block's first row, in leaf order as in row order; and
  // steps the rows as a whole-pool step that keeps the previous position in the pool's column.
  ForceSet forces = curlNoiseField(false);
  constexpr std::size_t kBlock = 8192, kRows = 20'000;  // blocks of 8192, 8192 and 3616 rows
  for (const AdvectionScheme scheme : kSchemes) {
    // Leaf order on coherent rows visits them in row order (LeafOrder::build() declines).
    for (const auto& [visits, coherent] : {std::pair{Visits::RowOrder, false},
                                           {Visits::LeafOrder, false},
                                           {Visits::LeafOrder, true}}) {
      const std::string what = std::string(advectionSchemeName(scheme)) +
                               (visits == Visits::LeafOrder ? ", leaf order" : ", row order") +
                               (coherent ? ", coherent" : ", scattered");
      ParticlePool reference(kRows), blocks(kRows);
      reference.keepPrevious();
      for (ParticlePool* pool : {&reference, &blocks}) {
        spawnAll(*pool, points(kRows, coherent), 0);
        pool->markAllStepped();
      }
      const StepTime time{0, kRate};
      Advection(scheme, Visits::RowOrder)
          .step(reference, forces, time, StepRows::wholePool(reference, true));
      Advection stepper(scheme, visits);
      std::vector<float> starts(3 * kBlock, -1.0f);
      for (std::size_t b = 0; b < kRows; b += kBlock) {
        const std::size_t e = std::min(kRows, b + kBlock);
        StepRows rows{RowRange{b, e}, e, true, false};
        for (std::size_t c = 0; c < 3; ++c) rows.starts[c] = starts.data() + c * kBlock;
        stepper.step(blocks, forces, time, rows);
        for (int c = 0; c < 3; ++c) {
          const float* written = starts.data() + static_cast<std::size_t>(c) * kBlock;
          ASSERT_EQ(std::memcmp(written, reference.previousPosition()[c].data() + b,
                                (e - b) * sizeof(float)),
                    0)
              << what << ": the starts of block " << b / kBlock << ", component " << c;
        }
      }
      EXPECT_FALSE(blocks.keepsPrevious()) << what;
      for (int c = 0; c < 3; ++c) {
        EXPECT_EQ(std::memcmp(blocks.position()[c].data(), reference.position()[c].data(),
                              kRows * sizeof(float)),
                  0)
            << what;
        EXPECT_EQ(std::memcmp(blocks.velocity()[c].data(), reference.velocity()[c].data(),
                              kRows * sizeof(float)),
                  0)
            << what;
      }
    }
  }
}

TEST(StepRowsPart, MovesTheStartsWithItsRows) {
  float x[200], y[200], z[200];
  const StepRows rows{RowRange{100, 300}, 250, false, false, {x, y, z}};
  const StepRows part = rows.partOf(RowRange{150, 200});
  EXPECT_EQ(part.rows.begin, 150u);
  EXPECT_EQ(part.rows.end, 200u);
  EXPECT_EQ(part.fresh, 250u);
  EXPECT_TRUE(part.serial);
  EXPECT_FALSE(part.keepPrevious);
  EXPECT_EQ(part.starts[0], x + 50);
  EXPECT_EQ(part.starts[1], y + 50);
  EXPECT_EQ(part.starts[2], z + 50);
  // No starts asked: none given to the part.
  const StepRows none{RowRange{100, 300}, 250, false, true};
  EXPECT_EQ(none.partOf(RowRange{150, 200}).starts[0], nullptr);
  EXPECT_TRUE(none.partOf(RowRange{150, 200}).keepPrevious);
}

TEST(LeafOrderedAdvection, SerialBlocksOfAFusedFrameMatchRowOrder) {
  // A fused frame hands each thread a block of rows to step serially: 10 000 rows here, an order
  // of 8192 rows and one of 1808.
  ForceSet forces = curlNoiseField(false);
  for (const AdvectionScheme scheme : kSchemes) {
    ParticlePool reference(30'000), leafOrdered(30'000);
    fillTwins(reference, leafOrdered, 25'000);
    Advection rows(scheme, Visits::RowOrder), leaves(scheme, Visits::LeafOrder);
    for (std::int64_t k = 0; k < 3; ++k) {
      rows.step(reference, forces, StepTime{k, kRate}, StepRows::wholePool(reference));
      for (std::size_t b = 0; b < leafOrdered.size(); b += 10'000) {
        const StepRows block{RowRange{b, std::min(leafOrdered.size(), b + 10'000)}, 0, true};
        leaves.step(leafOrdered, forces, StepTime{k, kRate}, block);
      }
      expectSameBits(reference, leafOrdered, std::string(advectionSchemeName(scheme)));
    }
  }
}

TEST(LeafOrderedAdvection, LargePoolsMatchRowOrderInLargerBlocks) {
  // 300 000 rows: blocks of 18 750 rows, each one task (LeafOrder::blockRows).
  ASSERT_EQ(LeafOrder::blockRows(300'000), 18'750u);
  ForceSet forces = curlNoiseField(false);
  for (const AdvectionScheme scheme : {AdvectionScheme::Euler, AdvectionScheme::RungeKutta4}) {
    ParticlePool reference(300'000), leafOrdered(300'000);
    fillTwins(reference, leafOrdered, 300'000);
    Advection rows(scheme, Visits::RowOrder), leaves(scheme, Visits::LeafOrder);
    tbb::task_arena two(2);
    for (std::int64_t k = 0; k < 2; ++k) {
      rows.step(reference, forces, StepTime{k, kRate}, StepRows::wholePool(reference));
      two.execute([&] {
        leaves.step(leafOrdered, forces, StepTime{k, kRate}, StepRows::wholePool(leafOrdered));
      });
      expectSameBits(reference, leafOrdered, std::string(advectionSchemeName(scheme)));
    }
  }
}

TEST(LeafOrderedAdvection, ChecksEveryRowOnceAfterItsStep) {
  // The non-finite check (afterEachTile) sees each row once, in tiles of consecutive rows, and
  // only once the row holds its new state.
  ForceSet forces = curlNoiseField(false);
  ParticlePool reference(20'000), leafOrdered(20'000);
  for (ParticlePool* pool : {&reference, &leafOrdered}) {
    spawnAll(*pool, points(20'000, false), 0);
    pool->markAllStepped();
  }
  Advection(AdvectionScheme::RungeKutta4, Visits::RowOrder)
      .step(reference, forces, StepTime{0, kRate}, StepRows::wholePool(reference, false));
  std::vector<int> seen(leafOrdered.size(), 0);
  std::size_t stale = 0;
  const RowPass check = [&](const Tile& tile) {
    EXPECT_LE(tile.rows().count(), static_cast<Eigen::Index>(Tile::kRows));
    for (std::size_t r = tile.rows().begin; r < tile.rows().end; ++r) {
      ++seen[r];
      stale += static_cast<std::size_t>(leafOrdered.position().x[static_cast<Eigen::Index>(r)] !=
                                        reference.position().x[static_cast<Eigen::Index>(r)]);
    }
  };
  tbb::task_arena one(1);
  one.execute([&] {
    Advection(AdvectionScheme::RungeKutta4, Visits::LeafOrder)
        .step(leafOrdered, forces, StepTime{0, kRate}, StepRows::wholePool(leafOrdered, false),
              check);
  });
  EXPECT_EQ(std::count(seen.begin(), seen.end(), 1), static_cast<std::ptrdiff_t>(seen.size()));
  EXPECT_EQ(stale, 0u);
}

// ---- the visiting order ------------------------------------------------------------------------

// A flow u(x) = (1, 2, 3) m/s whose blocks are cubes of 0.4 m, that logs the positions it
// samples: which rows a step visits, in which order (one thread only).
class LoggingFlow final : public ForceModule {
 public:
  explicit LoggingFlow(std::vector<Eigen::Vector3f>& log) : log_(&log) {}
  std::string_view typeName() const override { return "logging_flow"; }
  void accumulate(const ForceInput&, RowRange, Vec3Rows&) const override {}
  bool prescribesVelocity() const override { return true; }
  bool velocityFromPositionsOnly() const override { return true; }
  void accumulateVelocity(const ForceInput& in, RowRange rows, Vec3Rows& velocity) const override {
    const ConstVec3Rows p = in.position.rows(rows);
    for (Eigen::Index j = 0; j < rows.count(); ++j) {
      log_->emplace_back(p.x[j], p.y[j], p.z[j]);
      velocity.x[j] += 1.0f;
      velocity.y[j] += 2.0f;
      velocity.z[j] += 3.0f;
    }
  }
  bool sampleBlocks(const Vec3View& position, RowRange rows, BlockCoord* out) const override {
    const ConstVec3Rows p = position.rows(rows);
    for (Eigen::Index j = 0; j < rows.count(); ++j) out[j] = blockOf({p.x[j], p.y[j], p.z[j]});
    return true;
  }
  static BlockCoord blockOf(const Eigen::Vector3f& x) {
    if (!x.allFinite()) return {BlockCoord::kNowhere, 0, 0};
    const auto b = [](float v) { return static_cast<std::int32_t>(std::floor(v / 0.4f)); };
    return {b(x.x()), b(x.y()), b(x.z())};
  }

 private:
  std::vector<Eigen::Vector3f>* log_;
};

// The block's key in LeafOrder's counting sort over the box of [-1.2, 1.2]³ (blocks -3..2).
int keyOf(const Eigen::Vector3f& x) {
  const BlockCoord b = LoggingFlow::blockOf(x);
  return ((b.x + 3) * 6 + (b.y + 3)) * 6 + (b.z + 3);
}

// 8192 scattered points in a pool, under a flow that logs where it is sampled.
struct LoggedPool {
  std::vector<Eigen::Vector3f> log;
  ForceSet forces;
  ParticlePool pool{8192};
  const std::vector<Eigen::Vector3f> start = points(8192, false);

  LoggedPool() {
    forces.add(std::make_unique<LoggingFlow>(log));
    spawnAll(pool, start, 0);
  }
};

TEST(LeafOrderedAdvection, AnIntegratorVisitsScatteredRowsLeafByLeaf) {
  LoggedPool logged;
  const std::vector<Eigen::Vector3f>& log = logged.log;
  const std::vector<Eigen::Vector3f>& start = logged.start;
  ForceSet& forces = logged.forces;
  ParticlePool& pool = logged.pool;
  pool.markAllStepped();
  tbb::task_arena one(1);
  one.execute([&] { makeIntegrator("explicit_euler")->step(pool, forces, StepTime{0, kRate}); });
  ASSERT_EQ(log.size(), start.size());
  EXPECT_NE(log, start) << "visited in row order";
  std::vector<int> keys;
  for (const Eigen::Vector3f& x : log) keys.push_back(keyOf(x));
  EXPECT_TRUE(std::is_sorted(keys.begin(), keys.end()));
  std::vector<Eigen::Vector3f> sorted = start;
  std::stable_sort(sorted.begin(), sorted.end(),
                   [](const auto& a, const auto& b) { return keyOf(a) < keyOf(b); });
  EXPECT_EQ(log, sorted) << "rows of one block in their order";
  // And every row moved by h·u, in its own row.
  const float h = StepTime{0, kRate}.dt();
  for (std::size_t r = 0; r < start.size(); r += 997) {
    EXPECT_EQ(pool.position().x[static_cast<Eigen::Index>(r)], start[r].x() + h * 1.0f);
    EXPECT_EQ(pool.position().z[static_cast<Eigen::Index>(r)], start[r].z() + h * 3.0f);
  }
}

TEST(LeafOrderedAdvection, RowOrderVisitsRowsInOrder) {
  LoggedPool logged;
  const std::vector<Eigen::Vector3f>& log = logged.log;
  const std::vector<Eigen::Vector3f>& start = logged.start;
  ForceSet& forces = logged.forces;
  ParticlePool& pool = logged.pool;
  tbb::task_arena one(1);
  one.execute([&] {
    Advection(AdvectionScheme::Euler, Visits::RowOrder)
        .step(pool, forces, StepTime{0, kRate}, StepRows::wholePool(pool, false));
  });
  EXPECT_EQ(log, start);
}

TEST(LeafOrderedAdvection, AVectorFieldsBlocksAreItsGridsLeaves) {
  ForceSet forces = curlNoiseField(false);
  std::vector<Eigen::Vector3f> at = points(1000, false);
  const float inf = std::numeric_limits<float>::infinity();
  at.emplace_back(std::numeric_limits<float>::quiet_NaN(), 0.0f, 0.0f);
  at.emplace_back(0.0f, -inf, 0.0f);
  at.emplace_back(0.0f, 0.0f, 1e30f);  // beyond 2^30 voxels
  ParticlePool pool(at.size());
  spawnAll(pool, at, 0);
  std::vector<BlockCoord> blocks(at.size());
  ASSERT_TRUE(
      forces.sampleBlocks(Vec3View::of(pool.position()), RowRange{0, at.size()}, blocks.data()));
  for (std::size_t r = 0; r < 1000; ++r) {
    EXPECT_EQ(std::make_tuple(blocks[r].x, blocks[r].y, blocks[r].z), leafOf(at[r])) << r;
  }
  for (std::size_t r = 1000; r < at.size(); ++r) EXPECT_EQ(blocks[r].x, BlockCoord::kNowhere);
}

// ---- LeafOrder
// -----------------------------------------------------------------------------------

struct Ordered {
  bool built = false;
  std::vector<std::uint32_t> rows;
};

Ordered orderOf(const std::vector<Eigen::Vector3f>& at, RowRange rows) {
  std::vector<Eigen::Vector3f> unused;
  ForceSet forces;
  forces.add(std::make_unique<LoggingFlow>(unused));
  ParticlePool pool(at.size());
  spawnAll(pool, at, 0);
  LeafOrder order;
  Ordered o;
  o.built = order.build(forces, pool.position(), rows);
  if (o.built) o.rows.assign(order.rows(), order.rows() + order.size());
  return o;
}

TEST(LeafOrder, SortsScatteredRowsByBlockThenRow) {
  const std::vector<Eigen::Vector3f> at = points(9000, false);
  const RowRange rows{500, 500 + 8192};
  const Ordered o = orderOf(at, rows);
  ASSERT_TRUE(o.built);
  ASSERT_EQ(o.rows.size(), 8192u);
  std::vector<std::uint32_t> each = o.rows;
  std::sort(each.begin(), each.end());
  for (std::size_t j = 0; j < each.size(); ++j) ASSERT_EQ(each[j], rows.begin + j);
  for (std::size_t j = 1; j < o.rows.size(); ++j) {
    const int a = keyOf(at[o.rows[j - 1]]), b = keyOf(at[o.rows[j]]);
    ASSERT_TRUE(a < b || (a == b && o.rows[j - 1] < o.rows[j])) << j;
  }
}

TEST(LeafOrder, LeavesCoherentRowsAsTheyAre) {
  // In [-0.39, 0.39]³: the 8 blocks around the origin.
  std::vector<Eigen::Vector3f> at;
  for (std::size_t i = 0; i < 4096; ++i) at.push_back(weyl(i, 0.39f));
  std::stable_sort(at.begin(), at.end(),
                   [](const auto& a, const auto& b) { return keyOf(a) < keyOf(b); });
  EXPECT_FALSE(orderOf(at, RowRange{0, at.size()}).built);
  // One row in every 16 out of place is enough change of block to sort.
  for (std::size_t r = 0; r < at.size(); r += 16) std::swap(at[r], at[at.size() - 1 - r]);
  EXPECT_TRUE(orderOf(at, RowRange{0, at.size()}).built);
}

TEST(LeafOrder, PutsPositionsOutsideEveryBlockLast) {
  std::vector<Eigen::Vector3f> at = points(1000, false);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (std::size_t r = 0; r < at.size(); r += 100) at[r].y() = nan;
  const Ordered o = orderOf(at, RowRange{0, at.size()});
  ASSERT_TRUE(o.built);
  for (std::size_t j = 0; j < 10; ++j) {
    EXPECT_EQ(o.rows[o.rows.size() - 10 + j], 100 * j) << "in row order, after the others";
  }
}

TEST(LeafOrder, MergesBlocksOfAWideBoxIntoCoarserBuckets) {
  // Blocks from -2.5e6 to 2.5e6 a side: far more than kMaxBuckets, so blocks are merged, yet
  // the two clusters (x < 0, x > 0) still come out apart, each in its rows' order.
  std::vector<Eigen::Vector3f> at;
  for (std::size_t i = 0; i < 2000; ++i) {
    const float side = i % 2 == 0 ? -1e6f : 1e6f;
    at.emplace_back(side + static_cast<float>(i % 13), static_cast<float>(i % 7), 0.0f);
  }
  const Ordered o = orderOf(at, RowRange{0, at.size()});
  ASSERT_TRUE(o.built);
  for (std::size_t j = 0; j < 1000; ++j) {
    EXPECT_EQ(o.rows[j] % 2, 0u) << j;
    EXPECT_EQ(o.rows[1000 + j] % 2, 1u) << j;
  }
}

TEST(LeafOrder, NeedsAModuleWithBlocks) {
  ForceSet forces;
  forces.add(std::make_unique<AnalyticForce>(AnalyticField::uniform({1, 0, 0}),
                                             AnalyticForce::Mode::Advect, 1.0f));
  EXPECT_FALSE(forces.gathersVelocity());
  ParticlePool pool(100);
  spawnAll(pool, points(100, false), 0);
  LeafOrder order;
  EXPECT_FALSE(order.build(forces, pool.position(), RowRange{0, 100}));
}

}  // namespace
}  // namespace tickfx
