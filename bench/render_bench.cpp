// Preview render speed (issue 14, item 5): 10⁶ particles to a 1280×720 PNG through the
// preview's own path: colour each particle by speed (preview::ColourBy), render the frame
// (preview::renderFrame: ground grid and axis marks, every particle projected through the camera,
// the splats sorted far to near and drawn in parallel bands of rows), encode the PNG. One and all
// threads; the median of the repeats.
//
//   render_bench              10⁶ particles, 7 repeats
//   render_bench --quick      10⁵ particles, 3 repeats
//   render_bench --reps=9     repeats a thread count
//
// Output: a table, then `render ...: value unit` lines (BenchHarness.h's summary form).
#include <tbb/info.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <optional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "BenchHarness.h"
#include "app/preview/ColourBy.h"
#include "app/preview/FrameRenderer.h"
#include "app/preview/PinholeCamera.h"
#include "app/preview/SplatImage.h"
#include "io/cache/FrameData.h"

namespace {

namespace bench = tickfx::bench;
using bench::Clock;

struct Timing {
  double colour = 0.0, render = 0.0, png = 0.0;
  double total() const { return colour + render + png; }
};

double seconds(Clock::time_point from) {
  return std::chrono::duration<double>(Clock::now() - from).count();
}

// One frame, timed by stage; `bytes` gets the PNG's size (and keeps the work from being elided).
Timing renderOnce(const tickfx::io::FrameData& frame, const tickfx::preview::PinholeCamera& camera,
                  const tickfx::preview::RenderSettings& settings, std::size_t& bytes) {
  Timing t;
  auto start = Clock::now();
  const tickfx::preview::ColourBy speed = tickfx::preview::ColourBy::parse("speed", frame);
  const std::vector<tickfx::preview::Rgb> colours = speed.colours(frame, 0.0, 1.8);
  t.colour = seconds(start);
  start = Clock::now();
  const tickfx::preview::SplatImage image =
      tickfx::preview::renderFrame(camera, frame, colours, {}, settings);
  t.render = seconds(start);
  start = Clock::now();
  bytes = image.png().size();
  t.png = seconds(start);
  return t;
}

void usage(const char* argv0) {
  std::printf(
      "usage: %s [--quick] [--reps=COUNT]\n"
      "  --quick            smoke run: 1e5 particles, 3 repeats\n"
      "  --reps=7           repeats on each thread count (the median is reported)\n",
      argv0);
}

}  // namespace

int main(int argc, char** argv) {
  bench::CommandLine cl(usage);
  cl.timing.reps = 7;
  cl.quickTiming.reps = 3;
  cl.withoutMinTime();
  if (const std::optional<int> exitCode = cl.parse(argc, argv)) return *exitCode;
  const std::size_t n = cl.quick ? 100'000 : 1'000'000;
  const int repeats = cl.timing.reps;
  std::printf("render_bench: %zu particles in a 6 x 2 x 2 m box to a 1280x720 PNG (%s build)\n", n,
              TICKFX_BENCH_CONFIG);
  // Particles in a 6 x 2 x 2 m box, each with a velocity of up to about 1.7 m/s.
  std::mt19937 random(11);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  tickfx::io::FrameData frame;
  frame.resize(n, {});
  for (std::size_t i = 0; i < n; ++i) {
    const auto r = static_cast<Eigen::Index>(i);
    frame.id[i] = i;
    frame.position.x[r] = 3.0f * u(random);
    frame.position.y[r] = 1.0f + u(random);
    frame.position.z[r] = u(random);
    frame.velocity.x[r] = u(random);
    frame.velocity.y[r] = u(random);
    frame.velocity.z[r] = u(random);
  }
  const auto camera = tickfx::preview::PinholeCamera::framing(
      {-3, 0, -1}, {3, 2, 1}, Eigen::Vector3d::UnitY(), 40.0, 1280, 720);
  tickfx::preview::RenderSettings settings;
  settings.grid =
      tickfx::preview::GroundGrid::under({-3, 0, -1}, {3, 2, 1}, tickfx::preview::UpAxis::Y);
  settings.axisLength = 1.0;
  const int all = tbb::info::default_concurrency();
  std::vector<std::pair<int, Timing>> results;
  std::size_t bytes = 0;
  for (const int threads : bench::oneAndAll(all)) {
    tbb::task_arena arena(threads);
    std::vector<Timing> runs;
    arena.execute([&] {
      renderOnce(frame, camera, settings, bytes);  // warm-up: first-touch pages, TBB workers
      for (int r = 0; r < repeats; ++r) runs.push_back(renderOnce(frame, camera, settings, bytes));
    });
    std::sort(runs.begin(), runs.end(),
              [](const Timing& a, const Timing& b) { return a.total() < b.total(); });
    results.emplace_back(threads, runs[runs.size() / 2]);
  }
  std::printf("%8s %12s %12s %12s %12s\n", "threads", "colour s", "render s", "png s", "total s");
  for (const auto& [threads, t] : results) {
    std::printf("%8d %12.4f %12.4f %12.4f %12.4f\n", threads, t.colour, t.render, t.png, t.total());
  }
  std::printf("\n");
  const std::string size = bench::sizeLabel(n);
  for (const auto& [threads, t] : results) {
    std::printf(
        "render %s 1280x720 %s: %.3f s a frame (colour %.3f, render %.3f, png %.3f; "
        "%.2fx 1 thread; target < 1 s at 1e6; %zu bytes)\n",
        size.c_str(), bench::threadsLabel(threads).c_str(), t.total(), t.colour, t.render, t.png,
        results.front().second.total() / t.total(), bytes);
  }
  return 0;
}
