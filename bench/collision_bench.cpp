// Colliders: what a plane and a level set add to a gravity + drag tick of 10⁶ particles, with 1
// and 2 threads, and the level set's test against openvdb::tools::BoxSampler sampling the same
// grid at the same points.
//
//   collision_bench             10⁶ particles (under a minute on 2 cores)
//   collision_bench --quick     smoke run: 10⁵ particles, short timings
//   collision_bench --particles=N
//
// The scene: particles in a 20 m box from 1 m above the ground drifting at up to 2 m/s,
// semi-implicit Euler at 60 Hz, under gravity and drag (k = 2: they settle at 5 m/s), never
// removed. Every batch is 10 ticks from that state (restored, untimed), so that each case sees
// the same spray falling through the air whatever the timing's length: in 10 ticks none falls
// the 1 m to the ground (with batches grown to a time, a heap grew on it over the batch, and the
// plane's figure measured how long the batch was). Cases, each on its own system:
//   tick         ParticleSystem::step() with no collider, a tick at a time: the baseline.
//   plane        the same with the ground plane (y = 0) under the box: its collision pass screens
//                every particle's path a tick (what contacts cost is the next case).
//   resting      the plane with every particle resting on it (1 cm above, at rest): each touches
//                it every tick (gravity pulls it in by g·dt²), the worst case.
//   level set    the same spray with a level-set sphere of radius 2 m (voxel 5 cm, baked) in the
//                box: a path whose bounding box misses the sphere's band samples nothing.
//   collide      the level set's collision pass alone (ColliderSet::collide), on the spray.
//   BoxSampler   openvdb::tools::BoxSampler sampling the same sphere's grid once at the end of
//                every path the level set samples (those whose box meets the grid's), each block
//                with its own accessor: the baseline of what the pass does for the points it
//                samples.
// Targets: a plane <= 15 % of the tick (paired round by round: bench::pairedSpeedup()); collide
// <= 1.2 x BoxSampler.
//
// Output: the table, then one line a figure, `name: value unit (ratios, targets)`.
#include <openvdb/openvdb.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/SignedFloodFill.h>
#include <tbb/info.h>
#include <tbb/task_arena.h>

#include <cstdint>
#include <cstdio>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "BenchHarness.h"
#include "fields/ColliderSet.h"
#include "fields/ColliderShapes.h"
#include "fields/ForceSet.h"
#include "fields/Gravity.h"
#include "fields/LinearDrag.h"
#include "fields/vdb/LevelSetCollider.h"
#include "particles/ParallelFor.h"
#include "particles/ParticleSystem.h"

namespace {

namespace bench = tickfx::bench;
using tickfx::ColliderSettings;

// Ticks a batch of the system cases, each from the restored scene (see the top).
constexpr std::int64_t kBatchTicks = 10;

void usage(const char* argv0) {
  std::printf("usage: %s [--quick] [--particles=N] [--min-time=S] [--reps=N]\n", argv0);
}

ColliderSettings sphereLevelSet() {
  ColliderSettings s;
  s.type = tickfx::ColliderType::LevelSet;
  s.levelSet.source = tickfx::LevelSetSettings::Source::Bake;
  s.levelSet.radius = 2.0;
  s.levelSet.voxelSize = 0.05;
  s.levelSet.center = Eigen::Vector3d(0.0, 10.0, 0.0);
  return s;
}

std::unique_ptr<tickfx::ParticleSystem> scene(std::size_t n, int threads,
                                              std::optional<ColliderSettings> collider,
                                              bool resting = false) {
  tickfx::SystemSettings settings;
  settings.threads = threads;
  settings.maxParticles = n;
  tickfx::ForceSet forces;
  forces.add(std::make_unique<tickfx::Gravity>());
  forces.add(std::make_unique<tickfx::LinearDrag>(2.0f, Eigen::Vector3f::Zero()));
  tickfx::ColliderSet colliders;
  if (collider) {
    colliders.add(collider->type == tickfx::ColliderType::LevelSet
                      ? tickfx::makeLevelSetCollider(*collider)
                      : tickfx::makeCollider(*collider));
  }
  auto system = std::make_unique<tickfx::ParticleSystem>(
      settings, std::vector<tickfx::EmitterSettings>{}, std::move(forces),
      std::vector<tickfx::StructureSettings>{}, std::move(colliders));
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  for (std::size_t i = 0; i < n; ++i) {
    tickfx::ParticleInit init;
    init.position =
        Eigen::Vector3f(unit(rng) * 10.0f, 11.0f + unit(rng) * 10.0f, unit(rng) * 10.0f);
    init.velocity = Eigen::Vector3f(unit(rng), unit(rng), unit(rng)) * 2.0f;
    // None starts inside the level-set ball (radius 2 m at (0, 10, 0)): a spray falls onto it.
    if ((init.position - Eigen::Vector3f(0.0f, 10.0f, 0.0f)).norm() < 2.2f) {
      --i;
      continue;
    }
    if (resting) {
      init.position.y() = 0.01f;
      init.velocity.setZero();
    }
    system->editPool().spawn(init, 0);
  }
  return system;
}

}  // namespace

int main(int argc, char** argv) {
  std::optional<std::size_t> particles;
  bench::CommandLine cl(usage);
  cl.count("--particles", particles);
  if (const std::optional<int> exitCode = cl.parse(argc, argv)) return *exitCode;
  const std::size_t n = particles.value_or(cl.quick ? 100'000 : 1'000'000);
  openvdb::initialize();
  bench::printMachine(" (TBB default " + std::to_string(tbb::info::default_concurrency()) + ")");
  bench::printBuild();

  ColliderSettings plane;  // the ground, y = 0
  const ColliderSettings levelSet = sphereLevelSet();
  std::printf("\n%zu particles, gravity + drag, semi-implicit Euler at 60 Hz\n", n);
  std::printf("%-12s %-10s %12s %10s\n", "case", "threads", "ms/tick", "vs tick");
  for (const int threads : bench::oneAndAll(tbb::info::default_concurrency())) {
    auto none = scene(n, threads, std::nullopt);
    auto withPlane = scene(n, threads, plane);
    auto resting = scene(n, threads, plane, /*resting=*/true);
    auto withLevelSet = scene(n, threads, levelSet);
    for (int k = 0; k < 3; ++k) resting->step();  // settled on the ground
    // Snapshots with the previous positions colliders' paths start from (the collider-free
    // system's pool does not keep them).
    tickfx::ParticlePool spray = none->pool(), heap = resting->pool();
    spray.keepPrevious();
    // The level set's grid and box, and the paths whose box meets it (chosen once, as the
    // collision pass would choose them: both ends inside the grown box test).
    const tickfx::LevelSetInfo info = *tickfx::levelSetInfo(withLevelSet->colliders()->collider(0));
    std::vector<bench::Case> cases;
    // One step() at a time: stepTicks() would fuse the ticks of the collider-free system (a
    // system with colliders runs tick by tick), and the figure wanted is a tick's.
    const auto ticksOf = [](tickfx::ParticleSystem& s) {
      return [&s](std::int64_t t) {
        for (std::int64_t k = 0; k < t; ++k) s.step();
      };
    };
    cases.emplace_back("tick", ticksOf(*none));
    cases.emplace_back("plane", ticksOf(*withPlane));
    cases.emplace_back("resting", ticksOf(*resting));
    cases.emplace_back("level set", ticksOf(*withLevelSet));
    cases[0].before = [&] { none->editPool() = spray; };
    cases[1].before = [&] { withPlane->editPool() = spray; };
    cases[2].before = [&] { resting->editPool() = heap; };
    cases[3].before = [&] { withLevelSet->editPool() = spray; };
    for (bench::Case& c : cases) {
      c.calibrated = false;
      c.ticksPerFrame = kBatchTicks;
      c.warmUp = true;
    }
    tickfx::ColliderSet alone;
    alone.add(tickfx::makeLevelSetCollider(levelSet));
    tickfx::ParticlePool& pool = withLevelSet->editPool();
    cases.emplace_back("collide", [&](std::int64_t t) {
      tbb::task_arena arena(threads);
      arena.execute([&] {
        for (std::int64_t k = 0; k < t; ++k) alone.collide(pool, 0, 60, false);
      });
    });
    // The same sphere baked again here, OpenVDB's way (the collider keeps its grid to itself).
    const auto sdf = [&] {
      auto g = openvdb::FloatGrid::create(0.15f);
      g->setTransform(openvdb::math::Transform::createLinearTransform(0.05));
      auto acc = g->getAccessor();
      for (int i = -44; i <= 44; ++i)
        for (int j = 200 - 44; j <= 200 + 44; ++j)
          for (int k = -44; k <= 44; ++k) {
            const double d =
                std::sqrt(double(i * i) + double((j - 200) * (j - 200)) + double(k * k)) * 0.05 -
                2.0;
            if (std::abs(d) < 0.15) acc.setValue(openvdb::Coord(i, j, k), static_cast<float>(d));
          }
      openvdb::tools::signedFloodFill(g->tree(), /*threaded=*/false);
      return g;
    }();
    std::size_t sampled = 0;
    cases.emplace_back("BoxSampler", [&](std::int64_t t) {
      tbb::task_arena arena(threads);
      arena.execute([&] {
        for (std::int64_t k = 0; k < t; ++k) {
          std::vector<std::size_t> counts((pool.size() + tickfx::kParallelBlockRows - 1) /
                                          tickfx::kParallelBlockRows);
          tickfx::parallelForRows(pool.size(), [&](std::size_t b, std::size_t e) {
            const openvdb::FloatGrid::ConstAccessor acc = sdf->getConstAccessor();
            const auto& p = pool.position();
            const auto& q = pool.previousPosition();
            // The pass's own vectorised box screen, so that the two differ only in what they do
            // with a path that meets the grid's box.
            const float* const starts[3] = {q.x.data() + b, q.y.data() + b, q.z.data() + b};
            const float* const ends[3] = {p.x.data() + b, p.y.data() + b, p.z.data() + b};
            thread_local std::vector<std::uint8_t> flags;
            flags.assign(e - b, 0);
            tickfx::collide::screenBoxColumns(starts, ends, e - b, info.lo, info.hi, flags.data());
            float sum = 0.0f;
            std::size_t c = 0;
            for (std::size_t i = b; i < e; ++i) {
              if (flags[i - b] == 0) continue;
              const auto r = static_cast<Eigen::Index>(i);
              ++c;
              sum += openvdb::tools::BoxSampler::sample(
                  acc, sdf->transform().worldToIndex(openvdb::Vec3d(p.x[r], p.y[r], p.z[r])));
            }
            counts[b / tickfx::kParallelBlockRows] = c;
            bench::escape(&sum);
          });
          sampled = 0;
          for (const std::size_t c : counts) sampled += c;
        }
      });
    });
    cases[4].before = cases[3].before;
    cases[5].before = cases[3].before;
    bench::timeCases(cases, cl.timing);
    const double tick = cases[0].seconds();
    for (const bench::Case& c : cases) {
      std::printf("%-12s %-10s %12.3f %9.2fx\n", c.name.c_str(),
                  bench::threadsLabel(threads).c_str(), c.seconds() * 1e3, c.seconds() / tick);
    }
    const std::string at = bench::sizeLabel(n) + " particles, " + bench::threadsLabel(threads);
    // Paired round by round (the median of each round's plane / tick), then by the medians: the
    // two cases' medians move apart by half of a tick on a loaded guest.
    const double planeShare = bench::pairedSpeedup(cases[0], cases[1]) - 1.0;
    std::printf(
        "collision plane cost %s: %s ms/tick (%s%% of the tick paired, %s%% by the medians; "
        "target <= 15%%)\n",
        at.c_str(), bench::g3((cases[1].seconds() - tick) * 1e3).c_str(),
        bench::g3(planeShare * 100.0).c_str(),
        bench::g3((cases[1].seconds() - tick) / tick * 100.0).c_str());
    std::printf("collision plane resting cost %s: %s ms/tick (%s%% of the tick)\n", at.c_str(),
                bench::g3((cases[2].seconds() - tick) * 1e3).c_str(),
                bench::g3((cases[2].seconds() - tick) / tick * 100.0).c_str());
    std::printf("collision level set cost %s: %s ms/tick (%s%% of the tick)\n", at.c_str(),
                bench::g3((cases[3].seconds() - tick) * 1e3).c_str(),
                bench::g3((cases[3].seconds() - tick) / tick * 100.0).c_str());
    std::printf("collision level set vs BoxSampler %s: %s x (%zu paths sampled; target <= 1.2)\n",
                at.c_str(), bench::g3(cases[4].seconds() / cases[5].seconds()).c_str(), sampled);
  }
  return 0;
}
