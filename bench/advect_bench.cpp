// Advection through a baked OpenVDB field: tickfx against OpenVDB's two point advectors on the
// same grid, the same points, the same order, the same dt and the same thread count, in one run.
//
//   advect_bench                 10⁶ particles, orders 1 and 4, 1 and 2 threads
//   advect_bench --quick         smoke run: 10⁴ particles, short timings
//   advect_bench --count=N       N particles
//   advect_bench --min-time=0.5 --reps=9
//
// The field: seeded curl noise (|u| ≈ 1 m/s, wave number 2 rad/m) baked at 5 cm into a float grid
// over [−2, 2]³ m (81³ active voxels); the particles start on a Weyl sequence in [−1.5, 1.5]³
// and stay inside over a batch. Step 1/24 s. Two layouts of the same points:
//   scattered    in sequence order: consecutive particles are far apart, every sample a cache miss
//   coherent     sorted by leaf node (8³ voxels) then voxel, as particles born together and
//                moving together are: consecutive samples share leaves.
//
// Cases, each on its own copy of the points, one tick (one call, one step) at a time:
//   tickfx        Integrator::step on a ParticlePool whose only module is a VectorField in advect
//                 mode (explicit_euler → Euler, rk4 → RK4: integrators/Advection.h). SoA columns,
//                 particles visited leaf by leaf (integrators/LeafOrder.h), the pool's rows left
//                 where they are.
//   PointAdvect   openvdb::tools::PointAdvect<Vec3fGrid, std::vector<Vec3f>> with the integration
//                 order set and threading on (tbb::parallel_for over the points in their order;
//                 one accessor per TBB range). The same bits as tickfx (checked below).
//   advectPoints  openvdb::points::advectPoints on a PointDataGrid made from the same points
//                 (untimed) with the field grid's transform, so its leaves are the field's: each
//                 call advects in double through tools::VelocityIntegrator (float samples, cached
//                 per point: its default), then re-buckets every point into the leaf and voxel it
//                 moved to (points::movePoints), which tickfx does not do (it keeps rows in place
//                 and orders its visits instead). Positions are stored voxel-relative, so its bits
//                 are not tickfx's; the bench checks that the sums of the positions agree.
//                 One call a tick with timeSteps = 1, as a simulation writing each tick stepped.
// All run inside a tbb::task_arena of the case's thread count. Before each batch (untimed), the
// starting points are restored (a copy of the columns, of the vector, of the PointDataGrid), so
// every batch times the same trajectory from the same state.
//
// Output: the table, then one line a figure, `name: value unit (ratios, targets)`.
#include <openvdb/openvdb.h>
#include <openvdb/points/PointAdvect.h>
#include <openvdb/points/PointConversion.h>
#include <openvdb/tools/PointAdvect.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "BenchHarness.h"
#include "fields/ForceSet.h"
#include "fields/vdb/AnalyticField.h"
#include "fields/vdb/VectorField.h"
#include "fields/vdb/VectorFieldGrids.h"
#include "integrators/Integrator.h"

namespace {

namespace bench = tickfx::bench;
using tickfx::AnalyticField;
using tickfx::BakeSettings;

constexpr std::int64_t kStepRateHz = 24;

void usage(const char* argv0) {
  std::printf("usage: %s [--quick] [--count=N] [--min-time=SECONDS] [--reps=N]\n", argv0);
}

struct AdvectCase : bench::Case {
  AdvectCase(std::string caseName, std::function<void(std::int64_t)> runTicks, int caseOrder,
             int caseThreads, bool isOurs)
      : Case(std::move(caseName), std::move(runTicks)),
        order(caseOrder),
        threads(caseThreads),
        ours(isOurs) {}
  int order;
  int threads;
  bool ours;
};

std::vector<openvdb::Vec3f> startingPoints(std::size_t n) {
  std::vector<openvdb::Vec3f> points(n);
  const double a[3] = {0.7548776662466927, 0.5698402909980532, 0.3611333928711215};
  for (std::size_t i = 0; i < n; ++i) {
    for (int c = 0; c < 3; ++c) {
      points[i][c] =
          static_cast<float>(-1.5 + 3.0 * std::fmod(0.5 + a[c] * static_cast<double>(i + 1), 1.0));
    }
  }
  return points;
}

/// A pool holding `points`, at rest.
void load(tickfx::ParticlePool& pool, const std::vector<openvdb::Vec3f>& points) {
  if (pool.size() != points.size()) {
    for (const auto& p : points) {
      tickfx::ParticleInit init;
      init.position = Eigen::Vector3f(p.x(), p.y(), p.z());
      pool.spawn(init, 0);
    }
    pool.markAllStepped();
    return;
  }
  for (std::size_t i = 0; i < points.size(); ++i) {
    const auto r = static_cast<Eigen::Index>(i);
    pool.position().x[r] = points[i].x();
    pool.position().y[r] = points[i].y();
    pool.position().z[r] = points[i].z();
  }
}

/// The number of points of a PointDataGrid and the sum of their world positions' components.
std::pair<std::size_t, double> pointSum(const openvdb::points::PointDataGrid& points) {
  std::size_t n = 0;
  double sum = 0.0;
  const openvdb::math::Transform& xform = points.transform();
  for (auto leaf = points.tree().cbeginLeaf(); leaf; ++leaf) {
    const openvdb::points::AttributeHandle<openvdb::Vec3f> p(leaf->constAttributeArray("P"));
    for (auto voxel = leaf->beginValueOn(); voxel; ++voxel) {
      const openvdb::Vec3d ijk = voxel.getCoord().asVec3d();
      for (auto index = leaf->beginIndexVoxel(voxel.getCoord()); index; ++index) {
        const openvdb::Vec3d world = xform.indexToWorld(ijk + p.get(*index));
        sum += world.x() + world.y() + world.z();
        ++n;
      }
    }
  }
  return {n, sum};
}

}  // namespace

int main(int argc, char** argv) {
  std::optional<std::size_t> countGiven;
  bench::CommandLine cl(usage);
  cl.count("--count", countGiven, [](std::size_t n) { return n >= 1; });
  if (const std::optional<int> exitCode = cl.parse(argc, argv)) return *exitCode;
  const std::size_t count = countGiven ? *countGiven : cl.quick ? 10'000 : 1'000'000;

  openvdb::initialize();
  const AnalyticField noise = AnalyticField::curlNoise(3, 2.0, 1.0, 4);
  BakeSettings bake;
  bake.voxelSize = 0.05;
  bake.min = Eigen::Vector3d::Constant(-2.0);
  bake.max = Eigen::Vector3d::Constant(2.0);
  tickfx::VectorField::Settings settings;
  settings.file = "curl-noise (baked)";
  settings.mode = tickfx::VectorField::Mode::Advect;
  // One grid, handed to both.
  const openvdb::Vec3fGrid::Ptr grid = tickfx::bakeGrid(noise, bake);
  const tickfx::VectorField::Grids grids{{grid}};
  const std::vector<openvdb::Vec3f> scattered = startingPoints(count);
  std::vector<openvdb::Vec3f> coherentPoints = scattered;
  {
    const auto key = [&](const openvdb::Vec3f& p) {
      const openvdb::Coord ijk = grid->transform().worldToIndexCellCentered(p);
      const openvdb::Coord leaf = ijk >> 3;
      return std::make_tuple(leaf.z(), leaf.y(), leaf.x(), ijk.z(), ijk.y(), ijk.x());
    };
    std::stable_sort(coherentPoints.begin(), coherentPoints.end(),
                     [&](const auto& a, const auto& b) { return key(a) < key(b); });
  }
  const std::vector<openvdb::Vec3f>& coherent = coherentPoints;
  const float dt = tickfx::StepTime{0, kStepRateHz}.dt();

  std::printf(
      "advect_bench: %zu particles, curl noise baked at %.3g m (%llu active voxels), "
      "dt = 1/%lld s\n",
      count, bake.voxelSize, static_cast<unsigned long long>(grid->activeVoxelCount()),
      static_cast<long long>(kStepRateHz));
  bench::printMachine();
  bench::printBuild();

  // State kept per case so that the timed loop allocates nothing.
  struct Ours {
    tickfx::ParticlePool pool;
    tickfx::ForceSet forces;
    std::unique_ptr<tickfx::Integrator> integrator;
  };
  using PointGrid = openvdb::points::PointDataGrid;
  std::vector<std::unique_ptr<Ours>> ours;
  std::vector<std::unique_ptr<std::vector<openvdb::Vec3f>>> theirs;
  std::vector<std::unique_ptr<PointGrid::Ptr>> pointGrids;
  std::vector<std::unique_ptr<tbb::task_arena>> arenas;
  std::vector<AdvectCase> cases;  // in threes: tickfx, PointAdvect, advectPoints
  for (const std::vector<openvdb::Vec3f>* layout : {&scattered, &coherent}) {
    const std::vector<openvdb::Vec3f>& start = *layout;
    const char* layoutName = layout == &scattered ? "scattered" : "coherent";
    // Bucketed into the field's leaves and voxels once, untimed; each batch starts on a copy.
    const PointGrid::ConstPtr startGrid =
        openvdb::points::createPointDataGrid<openvdb::points::NullCodec, PointGrid>(
            start, grid->transform());
    for (const int order : {1, 4}) {
      for (const int threads : {1, 2}) {
        arenas.push_back(std::make_unique<tbb::task_arena>(threads));
        tbb::task_arena* arena = arenas.back().get();
        auto o = std::make_unique<Ours>(
            Ours{tickfx::ParticlePool(count), tickfx::ForceSet(),
                 tickfx::makeIntegrator(order == 1 ? "explicit_euler" : "rk4")});
        o->forces.add(std::make_unique<tickfx::VectorField>(settings, grids));
        load(o->pool, start);
        Ours* self = o.get();
        ours.push_back(std::move(o));
        AdvectCase& mine = cases.emplace_back(
            std::string(layoutName) + " tickfx",
            [=](std::int64_t ticks) {
              arena->execute([&] {
                for (std::int64_t k = 0; k < ticks; ++k) {
                  self->integrator->step(self->pool, self->forces, {k, kStepRateHz});
                }
              });
              bench::escape(self->pool.position().x.data());
            },
            order, threads, true);
        mine.before = [self, &start] { load(self->pool, start); };

        theirs.push_back(std::make_unique<std::vector<openvdb::Vec3f>>(start));
        std::vector<openvdb::Vec3f>* points = theirs.back().get();
        AdvectCase& pointAdvect = cases.emplace_back(
            std::string(layoutName) + " PointAdvect",
            [=, &grid](std::int64_t ticks) {
              openvdb::tools::PointAdvect<openvdb::Vec3fGrid, std::vector<openvdb::Vec3f>, false>
                  advector(*grid);
              advector.setIntegrationOrder(static_cast<unsigned>(order));
              advector.setThreaded(true);
              arena->execute([&] {
                for (std::int64_t k = 0; k < ticks; ++k) advector.advect(*points, dt, 1);
              });
              bench::escape(points->data());
            },
            order, threads, false);
        pointAdvect.before = [points, &start] { *points = start; };

        pointGrids.push_back(std::make_unique<PointGrid::Ptr>());
        PointGrid::Ptr* moved = pointGrids.back().get();
        AdvectCase& advectPoints = cases.emplace_back(
            std::string(layoutName) + " advectPoints",
            [=, &grid](std::int64_t ticks) {
              arena->execute([&] {
                for (std::int64_t k = 0; k < ticks; ++k) {
                  openvdb::points::advectPoints(**moved, *grid, static_cast<openvdb::Index>(order),
                                                static_cast<double>(dt), 1);
                }
              });
              bench::escape(moved->get());
            },
            order, threads, false);
        advectPoints.before = [moved, startGrid] { *moved = startGrid->deepCopy(); };
      }
    }
  }

  // Same trajectory: one batch of 3 ticks each, then compare. PointAdvect must give the same
  // bits; advectPoints (double, voxel-relative positions, its own point order) the same sum of
  // positions to float rounding.
  for (std::size_t i = 0; i < cases.size(); i += 3) {
    for (std::size_t j = i; j < i + 3; ++j) {
      if (cases[j].before) cases[j].before();
      cases[j].run(3);
    }
    const tickfx::ParticlePool& pool = ours[i / 3]->pool;
    const std::vector<openvdb::Vec3f>& points = *theirs[i / 3];
    std::size_t differ = 0;
    for (std::size_t r = 0; r < count; ++r) {
      const auto e = static_cast<Eigen::Index>(r);
      differ += pool.position().x[e] != points[r].x() || pool.position().y[e] != points[r].y() ||
                pool.position().z[e] != points[r].z();
    }
    const auto [moved, sum] = pointSum(**pointGrids[i / 3]);
    std::printf(
        "%s, order %d, %d thread(s) after 3 steps: %zu of %zu positions differ from "
        "PointAdvect's; advectPoints: %zu points, mean position differs by %.2e m\n",
        cases[i].name.c_str(), cases[i].order, cases[i].threads, differ, count, moved,
        std::abs(sum - bench::positionSum(pool)) / (3.0 * static_cast<double>(count)));
  }

  bench::timeCases(cases, cl.timing);

  std::printf("\n%-6s %-8s %-24s %16s %12s %12s %13s\n", "order", "threads", "case",
              "particle-steps/s", "ms/step", "PointAdvect", "advectPoints");
  // Each case against both baselines, which follow the tickfx case.
  for (std::size_t i = 0; i < cases.size(); i += 3) {
    const AdvectCase& pointAdvect = cases[i + 1];
    const AdvectCase& advectPoints = cases[i + 2];
    for (std::size_t j = i; j < i + 3; ++j) {
      const AdvectCase& c = cases[j];
      const double t = c.seconds();
      std::printf("%-6d %-8d %-24s %16.3e %12.3f %12.2f %13.2f\n", c.order, c.threads,
                  c.name.c_str(), static_cast<double>(count) / t, 1e3 * t,
                  bench::speedup(c, pointAdvect), bench::speedup(c, advectPoints));
    }
  }
  std::printf(
      "\nratios: the baseline's time per step over the case's (> 1: faster than the baseline); "
      "restoring the starting points is not timed.\n");

  // The summary, one line a figure (BenchHarness.h).
  std::printf("\n");
  for (std::size_t i = 0; i < cases.size(); i += 3) {
    const AdvectCase& c = cases[i];
    const AdvectCase& pointAdvect = cases[i + 1];
    const AdvectCase& advectPoints = cases[i + 2];
    std::printf(
        "advect order %d %s %s %s: %.2fx advectPoints paired round by round (target >= 2x; "
        "%.2fx by the medians), %.2fx PointAdvect, %s particle-steps/s (advectPoints %s, "
        "PointAdvect %s",
        c.order, bench::threadsLabel(c.threads).c_str(), c.name.substr(0, c.name.find(' ')).c_str(),
        bench::sizeLabel(count).c_str(), bench::pairedSpeedup(c, advectPoints),
        bench::speedup(c, advectPoints), bench::speedup(c, pointAdvect),
        bench::g3(static_cast<double>(count) / c.seconds()).c_str(),
        bench::g3(static_cast<double>(count) / advectPoints.seconds()).c_str(),
        bench::g3(static_cast<double>(count) / pointAdvect.seconds()).c_str());
    if (c.threads > 1) std::printf("; %.2f of %d cores busy", c.cores(), c.threads);
    std::printf(")\n");
  }
  return 0;
}
