// Spring networks: a 256 × 256 cloth (structural + shear + bend springs) hanging from its top edge
// under gravity, semi-implicit Euler at 60 Hz, with 1 and 2 threads.
//
//   spring_bench                  the 256 × 256 cloth (under 10 s on 2 cores)
//   spring_bench --quick          smoke run: a 64 × 64 cloth, short timings
//   spring_bench --side=128       a side × side cloth
//   spring_bench --min-time=0.5 --reps=9
//
// What counts as a spring evaluation: the network gathers, so every force evaluation computes each
// spring twice, once from each end (each end sums the forces of its own springs). One spring
// computed at one end is one "spring evaluation"; a tick of semi-implicit Euler (one force
// evaluation) makes 2·S of them for S springs. The table also gives springs per second (S per force
// evaluation, each spring once) and ticks per second.
//
// Cases, each on its own system built from the same cloth:
//   step()          ParticleSystem::step(): structure birth (tick 0 only), SpringNetwork::beginTick
//                   (ids to rows, per-particle link lists), the force evaluation and the update,
//                   ages and removal of the dead: what a tick costs a user.
//   evaluate        ForceSet::evaluate over every row in blocks of kParallelBlockRows, as an
//                   integrator's force pass does: gravity and the springs' gather only.
//   beginTick       SpringNetwork::beginTick alone on an unchanged cloth: the tables kept from the
//                   tick before (the rows' version compared; no spring here can break). What a
//                   tick of a cloth that neither tears nor loses particles pays; a tick that
//                   changes the springs rebuilds them on one thread (2.9 ms at 256², README).
// Each of step() and evaluate runs with 1 and with 2 threads; the table gives the ratio 2 / 1.
//
// Timing as in tick_bench (BenchHarness.h): batches of ticks sized to min-time/reps seconds, the
// cases taking turns batch by batch; a case's figure is the median over its batches of the time
// per tick.
//
// Output: the table, then one line a figure, `name: value unit (ratios, targets)`.
#include <tbb/info.h>
#include <tbb/task_arena.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "BenchHarness.h"
#include "fields/ForceSet.h"
#include "fields/Gravity.h"
#include "fields/SpringNetwork.h"
#include "particles/ParallelFor.h"
#include "particles/ParticleSystem.h"
#include "particles/StateHash.h"
#include "particles/Structure.h"

namespace {

namespace bench = tickfx::bench;

constexpr std::int64_t kStepRateHz = 60;

// A curtain of side × side particles 1 cm apart hanging from its top edge: 10 g a particle,
// k = 5 N/m (shear 2.5, bend 0.5), c = 0.01 N·s/m. Stable for semi-implicit Euler at 60 Hz: the
// stiffest mode has ω² ≤ 2·Σk/m = 12.8·k/m = 6400 s⁻², so ω·dt ≤ 1.33 < 2, and the damping keeps
// (ω·dt)² + 2·(24·c/m)·dt = 1.78 + 0.8 below 4. The cloth stretches a lot under its own weight
// (soft springs), which changes nothing in the cost of a spring; the run checks that it stays
// finite.
tickfx::StructureSettings curtain(int side) {
  tickfx::StructureSettings s;
  s.name = "curtain";
  tickfx::ClothShape cloth;
  cloth.origin = Eigen::Vector3d(-0.005 * side, 2.0, 0.0);
  cloth.axisU = Eigen::Vector3d::UnitX();
  cloth.axisV = Eigen::Vector3d(0.0, -0.6, 0.8);  // slanted, so it swings as it falls
  cloth.width = side;
  cloth.height = side;
  cloth.spacing = 0.01;
  cloth.pins = tickfx::ClothPins::TopEdge;
  s.shape = cloth;
  s.mass = 0.01;
  s.stiffness = 5.0;
  s.damping = 0.01;
  return s;
}

std::unique_ptr<tickfx::ParticleSystem> makeSystem(int side, int threads) {
  tickfx::SystemSettings settings;
  settings.stepRateHz = kStepRateHz;
  settings.integrator = "semi_implicit_euler";
  settings.maxParticles = static_cast<std::size_t>(side) * static_cast<std::size_t>(side);
  settings.threads = threads;
  tickfx::ForceSet forces;
  forces.add(std::make_unique<tickfx::Gravity>(Eigen::Vector3f(0.0f, -9.81f, 0.0f)));
  auto system = std::make_unique<tickfx::ParticleSystem>(
      settings, std::vector<tickfx::EmitterSettings>{}, std::move(forces),
      std::vector<tickfx::StructureSettings>{curtain(side)});
  system->step();  // tick 0: the cloth is born
  return system;
}

bool allFinite(const tickfx::ParticlePool& pool) {
  const auto n = static_cast<Eigen::Index>(pool.size());
  for (int c = 0; c < 3; ++c) {
    if (!pool.position()[c].head(n).allFinite() || !pool.velocity()[c].head(n).allFinite())
      return false;
  }
  return true;
}

// ---- timing ----------------------------------------------------------------------------------

// What the table needs beyond the timing: the spring columns and the 2-thread / 1-thread ratio.
struct Case : bench::Case {
  Case(std::string caseName, double evaluationsPerTick, int caseThreads,
       std::function<void(std::int64_t)> runTicks)
      : bench::Case(std::move(caseName), std::move(runTicks)),
        evaluations(evaluationsPerTick),
        threads(caseThreads) {}

  double evaluations;  // force evaluations per tick (0: the case evaluates no spring)
  int threads;
};

struct Options {
  int side = 256;
  bench::Timing timing;
};

void usage(const char* argv0) {
  std::printf(
      "usage: %s [--quick] [--side=N] [--min-time=SECONDS] [--reps=COUNT]\n"
      "  --quick            smoke run: --side=64 --min-time=0.02\n"
      "  --side=256         the cloth is side x side particles (default 256)\n"
      "  --min-time=0.3     seconds each case is timed\n"
      "  --reps=5           minimum number of timed batches per case (the median is reported)\n",
      argv0);
}

}  // namespace

int main(int argc, char** argv) {
  std::optional<std::size_t> side;
  bench::CommandLine cl(usage);
  cl.count(
      "--side", side, [](std::size_t s) { return s >= 2 && s <= 1000; }, " (2 to 1000)");
  if (const std::optional<int> exitCode = cl.parse(argc, argv)) return *exitCode;
  Options o;
  o.timing = cl.timing;
  if (cl.quick) o.side = 64;
  if (side) o.side = static_cast<int>(*side);

  std::printf(
      "spring_bench: a %d x %d cloth (structural + shear + bend springs), gravity,\n"
      "semi-implicit Euler at %lld Hz\n",
      o.side, o.side, static_cast<long long>(kStepRateHz));
  bench::printMachine(" (TBB default " + std::to_string(tbb::info::default_concurrency()) + ")");
  bench::printBuild();

  // One system per case, so that no case's ticks move another's state.
  std::unique_ptr<tickfx::ParticleSystem> step1 = makeSystem(o.side, 1);
  std::unique_ptr<tickfx::ParticleSystem> step2 = makeSystem(o.side, 2);
  std::unique_ptr<tickfx::ParticleSystem> eval = makeSystem(o.side, 1);
  std::unique_ptr<tickfx::ParticleSystem> table = makeSystem(o.side, 1);
  const std::size_t particles = step1->pool().size();
  const std::size_t springs = step1->springs()->springs().size();
  std::printf(
      "particles: %zu, springs: %zu, spring evaluations per force evaluation: %zu (each\n"
      "spring from both ends)\n",
      particles, springs, 2 * springs);

  // The bits do not depend on the thread count: one more tick on each, then compare.
  step1->step();
  step2->step();
  const bool same = tickfx::stateHash(step1->pool()) == tickfx::stateHash(step2->pool());
  std::printf("check after tick 1, 1 vs 2 threads: %s (hash %s)\n", same ? "same bits" : "MISMATCH",
              tickfx::hashToHex(tickfx::stateHash(step1->pool())).c_str());

  // The evaluate cases: the force pass an integrator runs, over the same blocks of rows.
  tickfx::ParticlePool& evalPool = eval->editPool();
  const tickfx::ForceSet& evalForces = eval->forces();
  tickfx::Vec3Column acceleration;
  acceleration.resize(static_cast<Eigen::Index>(particles));
  tbb::task_arena arena1(1), arena2(2);
  const auto evaluate = [&](tbb::task_arena& arena, std::int64_t ticks) {
    arena.execute([&] {
      for (std::int64_t i = 0; i < ticks; ++i) {
        const tickfx::ForceInput in{evalPool, tickfx::Vec3View::of(evalPool.position()),
                                    tickfx::Vec3View::of(evalPool.velocity()),
                                    tickfx::TickInstant{1, 0, 60}};
        tickfx::parallelForRows(particles, [&](std::size_t b, std::size_t e) {
          tickfx::Vec3Rows a = tickfx::Vec3Rows::of(acceleration, tickfx::RowRange{b, e});
          evalForces.evaluate(in, tickfx::RowRange{b, e}, a);
        });
        bench::escape(acceleration.x.data());
      }
    });
  };
  eval->springs()->beginTick(evalPool, 1);  // the tables for the state evaluated

  std::vector<Case> cases;
  cases.emplace_back("step(), 1 thread", 1.0, 1, [&](std::int64_t ticks) {
    for (std::int64_t i = 0; i < ticks; ++i) step1->step();
  });
  cases.emplace_back("step(), 2 threads", 1.0, 2, [&](std::int64_t ticks) {
    for (std::int64_t i = 0; i < ticks; ++i) step2->step();
  });
  cases.emplace_back("evaluate, 1 thread", 1.0, 1,
                     [&](std::int64_t ticks) { evaluate(arena1, ticks); });
  cases.emplace_back("evaluate, 2 threads", 1.0, 2,
                     [&](std::int64_t ticks) { evaluate(arena2, ticks); });
  const std::int64_t tableTick = table->tickCount();
  cases.emplace_back("beginTick alone", 0.0, 1, [&](std::int64_t ticks) {
    // On an unchanged state (no deaths, no breaks) the tables of the tick before are kept.
    for (std::int64_t i = 0; i < ticks; ++i) table->springs()->beginTick(table->pool(), tableTick);
  });

  bench::timeCases(cases, o.timing);

  // "cores": CPU time over wall time while the case ran. A 2-thread case near 1.0 had only one
  // core to itself (another process busy on the other), and its ratio says nothing of tickfx.
  std::printf("\n%-22s %11s %11s %15s %13s %9s %6s  %s\n", "case", "ms/tick", "ticks/s",
              "spring evals/s", "springs/s", "2t / 1t", "cores", "batches (min to max ms)");
  std::vector<double> seconds;
  for (const Case& c : cases) seconds.push_back(c.seconds());
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const Case& c = cases[i];
    const double s = seconds[i];
    const double perSpring = static_cast<double>(springs) / s;  // each spring once
    char evals[32] = "-", ratio[16] = "";
    if (c.evaluations > 0.0)
      std::snprintf(evals, sizeof evals, "%.4g", 2.0 * c.evaluations * perSpring);
    // The 2-thread case against its 1-thread baseline, the case before it.
    if (c.threads == 2) std::snprintf(ratio, sizeof ratio, "%.2f", bench::speedup(c, cases[i - 1]));
    std::printf("%-22s %11.4f %11.1f %15s %13.4g %9s %6.2f  %zu x %lld (%.3f to %.3f)\n",
                c.name.c_str(), 1e3 * s, 1.0 / s, evals, perSpring, ratio, c.cores(),
                c.secondsPerTick.size(), static_cast<long long>(c.batch), 1e3 * c.fastest(),
                1e3 * c.slowest());
  }

  const bool finite =
      allFinite(step1->pool()) && allFinite(step2->pool()) && allFinite(eval->pool());
  std::printf("\nticks run: %lld (1 thread), %lld (2 threads); cloth state finite: %s\n",
              static_cast<long long>(step1->tickCount()),
              static_cast<long long>(step2->tickCount()), finite ? "yes" : "NO");
  std::printf("checksum of final positions: %.9g\n", bench::positionSum(step1->pool()) +
                                                         bench::positionSum(step2->pool()) +
                                                         static_cast<double>(acceleration.y.sum()));
  if (!same) std::printf("CHECK FAILED: 1 and 2 threads disagree after one tick\n");
  if (!finite) std::printf("CHECK FAILED: the cloth blew up; the figures time NaN arithmetic\n");

  // The summary, one line a figure (BenchHarness.h).
  const std::string size = std::to_string(o.side) + "^2";
  const char* z = size.c_str();
  const double evaluations = 2.0 * static_cast<double>(springs);
  const double n = static_cast<double>(particles);
  std::printf("\n");
  std::printf(
      "springs step 1 thread %s: %s particle-steps/s (%s spring evaluations/s, %s ms a tick)\n", z,
      bench::g3(n / seconds[0]).c_str(), bench::g3(evaluations / seconds[0]).c_str(),
      bench::g3(1e3 * seconds[0]).c_str());
  std::printf(
      "springs step 2 threads %s: %.2fx 1 thread (target >= 1.8x), %s particle-steps/s (%s spring "
      "evaluations/s, %s ms a tick; %.2f of 2 cores busy)\n",
      z, seconds[0] / seconds[1], bench::g3(n / seconds[1]).c_str(),
      bench::g3(evaluations / seconds[1]).c_str(), bench::g3(1e3 * seconds[1]).c_str(),
      cases[1].cores());
  std::printf("springs evaluate 1 thread %s: %s spring evaluations/s (%s ms a tick)\n", z,
              bench::g3(evaluations / seconds[2]).c_str(), bench::g3(1e3 * seconds[2]).c_str());
  std::printf(
      "springs evaluate 2 threads %s: %.2fx 1 thread, %s spring evaluations/s (%s ms a tick; "
      "%.2f of 2 cores busy)\n",
      z, seconds[2] / seconds[3], bench::g3(evaluations / seconds[3]).c_str(),
      bench::g3(1e3 * seconds[3]).c_str(), cases[3].cores());
  std::printf("springs beginTick %s: %s ms (tables kept; %.0f %% of a 1-thread step())\n", z,
              bench::g3(1e3 * seconds[4]).c_str(), 100.0 * seconds[4] / seconds[0]);
  return same && finite ? 0 : 1;
}
