// Sub-emitters and attributes over life (issue 32): what attribute ramps cost a tick (nothing is
// the target: they are evaluated when a frame is shown, never in a tick), what evaluating them for
// a frame costs, and what an event and its children cost.
//
//   events_bench             10⁶ particles, 10⁴ deaths of 10 children each (under a minute)
//   events_bench --quick     smoke run: 10⁵ particles, 10³ deaths
//   events_bench --particles=N --events=E --children=C
//
// Cases, each on its own system at 60 Hz under gravity, semi-implicit Euler, every batch from a
// saved state (restored untimed):
//   tick         N particles born at t = 0 that never die: step(), the baseline.
//   ramps        the same emitter with Cd, Alpha and pscale as ramps over life: the same tick.
//   deaths       N particles and E more that die in the batch's first tick (no sub-emitter).
//   events       the same with a sub-emitter of C children on each death: the first tick finds
//                the deaths, the second spawns their children. Batches are those two ticks.
// And, outside the tick, a frame's attributes: ParticleSystem::copyColumn() of the five ramp
// columns (Cd_r, Cd_g, Cd_b, Alpha, pscale) against copying five stored columns.
//
// Output: the table, then one line a figure, `name: value unit (ratios)`.
#include <tbb/info.h>
#include <tbb/task_arena.h>

#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "BenchHarness.h"
#include "fields/ForceSet.h"
#include "fields/Gravity.h"
#include "particles/ParticleSystem.h"

namespace {

namespace bench = tickfx::bench;
using tickfx::EmitterSettings;
using tickfx::LifeAttributeSettings;
using tickfx::RampKey;

void usage(const char* argv0) {
  std::printf(
      "usage: %s [--quick] [--particles=N] [--events=E] [--children=C] [--min-time=S] "
      "[--reps=N]\n",
      argv0);
}

LifeAttributeSettings ramp(const std::string& name, std::vector<RampKey> keys) {
  LifeAttributeSettings a;
  a.name = name;
  a.kind = LifeAttributeSettings::Kind::Ramp;
  a.keys = std::move(keys);
  a.interpolation = tickfx::RampInterpolation::Smooth;
  return a;
}

EmitterSettings bulk(std::size_t n, bool ramps) {
  EmitterSettings e;
  e.name = "bulk";
  e.shape = tickfx::BoxShape{Eigen::Vector3d(20.0, 20.0, 20.0)};
  e.bursts = {tickfx::Burst{0.0, n}};
  e.speed = 2.0;
  e.spreadDegrees = 180.0;
  e.lifetime = 1e6;  // never dies here, but has a life for nage
  if (ramps) {
    e.attributes = {
        ramp("Cd", {RampKey{0.0f, {1.0f, 1.0f, 1.0f}}, RampKey{0.3f, {1.0f, 0.5f, 0.1f}},
                    RampKey{1.0f, {0.3f, 0.0f, 0.0f}}}),
        ramp("Alpha", {RampKey{0.0f, {1.0f}}, RampKey{1.0f, {0.0f}}}),
        ramp("pscale", {RampKey{0.0f, {0.05f}}, RampKey{1.0f, {0.01f}}})};
  }
  return e;
}

std::unique_ptr<tickfx::ParticleSystem> make(std::vector<EmitterSettings> emitters, int threads) {
  tickfx::SystemSettings s;
  s.stepRateHz = 60;
  s.threads = threads;
  s.maxParticles = 100'000'000;
  tickfx::ForceSet forces;
  forces.add(std::make_unique<tickfx::Gravity>(Eigen::Vector3f(0.0f, -9.81f, 0.0f)));
  return std::make_unique<tickfx::ParticleSystem>(s, emitters, std::move(forces));
}

// A system, its state before the timed batch and that batch's first tick.
struct Scene {
  std::unique_ptr<tickfx::ParticleSystem> system;
  tickfx::ParticlePool saved{0};
  std::int64_t tick = 0;
};

Scene scene(std::vector<EmitterSettings> emitters, int threads, std::int64_t warm) {
  Scene s{make(std::move(emitters), threads)};
  s.system->stepTicks(warm);
  s.saved = s.system->pool();
  s.tick = s.system->tickCount();
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  std::optional<std::size_t> particles, events, children;
  bench::CommandLine cl(usage);
  cl.count("--particles", particles);
  cl.count("--events", events);
  cl.count("--children", children);
  if (const std::optional<int> exitCode = cl.parse(argc, argv)) return *exitCode;
  const std::size_t n = particles.value_or(cl.quick ? 100'000 : 1'000'000);
  const std::size_t e = events.value_or(cl.quick ? 1'000 : 10'000);
  const std::size_t c = children.value_or(10);
  bench::printMachine(" (TBB default " + std::to_string(tbb::info::default_concurrency()) + ")");
  bench::printBuild();
  std::printf("\n%zu particles; %zu deaths of %zu children each; semi-implicit Euler at 60 Hz\n", n,
              e, c);
  std::printf("%-12s %-10s %12s\n", "case", "threads", "ms/tick");
  for (const int threads : bench::oneAndAll(tbb::info::default_concurrency())) {
    // Shells: E particles that die in tick 29 (a life of 30 ticks, 0.5 s).
    EmitterSettings shells;
    shells.name = "shells";
    shells.bursts = {tickfx::Burst{0.0, e}};
    shells.speed = 5.0;
    shells.spreadDegrees = 180.0;
    shells.lifetime = 0.5;
    EmitterSettings sparks;
    sparks.name = "sparks";
    sparks.sub.parent = "shells";
    sparks.sub.on = tickfx::EmitterEvent::Death;
    sparks.sub.countMin = sparks.sub.countMax = c;
    sparks.speed = 3.0;
    sparks.spreadDegrees = 180.0;
    sparks.lifetime = 1.0;
    std::vector<Scene> scenes;
    scenes.push_back(scene({bulk(n, false)}, threads, 29));
    scenes.push_back(scene({bulk(n, true)}, threads, 29));
    scenes.push_back(scene({bulk(n, false), shells}, threads, 29));
    scenes.push_back(scene({bulk(n, false), shells, sparks}, threads, 29));
    std::vector<bench::Case> cases;
    const char* names[] = {"tick", "ramps", "deaths", "events"};
    for (std::size_t k = 0; k < scenes.size(); ++k) {
      Scene& s = scenes[k];
      cases.emplace_back(names[k], [&s](std::int64_t t) {
        for (std::int64_t i = 0; i < t; ++i) s.system->step();
      });
      cases.back().before = [&s] {
        s.system->editPool() = s.saved;
        s.system->restoreClock(s.tick, nullptr);
      };
      cases.back().calibrated = false;
      cases.back().warmUp = true;
      cases.back().ticksPerFrame = 2;
    }
    // A frame's attributes: five evaluated columns against five stored ones copied.
    Scene& ramped = scenes[1];
    std::vector<float> out(ramped.system->pool().size() + c * e);
    const std::vector<std::string> columns = {"Cd_r", "Cd_g", "Cd_b", "Alpha", "pscale"};
    const auto copyAll = [&](tickfx::ParticleSystem& s, const std::vector<std::string>& which) {
      tbb::task_arena arena(threads);
      arena.execute([&] {
        for (const std::string& name : which) {
          s.copyColumn(name, tickfx::FloatDestination{out.data(), sizeof(float), out.size()});
        }
      });
      bench::escape(out.data());
    };
    cases.emplace_back("evaluate", [&](std::int64_t t) {
      for (std::int64_t i = 0; i < t; ++i) copyAll(*ramped.system, columns);
    });
    cases.emplace_back("copy", [&](std::int64_t t) {
      const std::vector<std::string> stored = {"mass", "lifetime", "mass", "lifetime", "mass"};
      for (std::int64_t i = 0; i < t; ++i) copyAll(*scenes[0].system, stored);
    });
    bench::timeCases(cases, cl.timing);
    for (const bench::Case& k : cases) {
      std::printf("%-12s %-10s %12.3f\n", k.name.c_str(), bench::threadsLabel(threads).c_str(),
                  k.seconds() * 1e3);
    }
    const std::string at = bench::sizeLabel(n) + " particles, " + bench::threadsLabel(threads);
    const double tick = cases[0].seconds();
    std::printf("ramps tick (%s): %s ms (%+.1f %% of the tick without them; target: the same)\n",
                at.c_str(), bench::g3(cases[1].seconds() * 1e3).c_str(),
                (cases[1].seconds() - tick) / tick * 100.0);
    // Each batch is two ticks: the deaths, then the children.
    const double perEvent =
        (cases[3].seconds() - cases[2].seconds()) * 2.0 / static_cast<double>(e);
    std::printf(
        "events (%s): %s ns an event, %s ns a child (%zu deaths of %zu children over "
        "the same deaths without a sub-emitter)\n",
        at.c_str(), bench::g3(perEvent * 1e9).c_str(),
        bench::g3(perEvent / static_cast<double>(c) * 1e9).c_str(), e, c);
    std::printf(
        "frame attributes (%s): %s ns a particle for Cd, Alpha and pscale (%s x copying "
        "five stored columns)\n",
        at.c_str(), bench::g3(cases[4].seconds() / static_cast<double>(n) * 1e9).c_str(),
        bench::g3(cases[4].seconds() / cases[5].seconds()).c_str());
  }
  return 0;
}
