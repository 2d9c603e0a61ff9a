// Preview render speed (issue 14, item 5): 10⁶ particles to a 1280×720 PNG, as `tickfx preview`
// draws a frame: project every particle through the camera, draw the splats (sorted far to near,
// in parallel bands of rows), encode the PNG. One and all threads; the median of the repeats.
//
//   render_bench              10⁶ particles, 7 repeats
//   render_bench --quick      10⁵ particles, 3 repeats
//
// Output: a table, then `render ...: value unit` lines (BenchHarness.h's summary form).
#include <tbb/info.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "io/preview/ColourMap.h"
#include "io/preview/PinholeCamera.h"
#include "io/preview/SplatImage.h"

namespace {

using Clock = std::chrono::steady_clock;

struct Timing {
  double project = 0.0, draw = 0.0, png = 0.0;
  double total() const { return project + draw + png; }
};

double seconds(Clock::time_point from) {
  return std::chrono::duration<double>(Clock::now() - from).count();
}

// One frame, timed by stage; `bytes` gets the PNG's size (and keeps the work from being elided).
Timing renderOnce(const std::vector<Eigen::Vector3d>& points,
                  const tickfx::io::PinholeCamera& camera, std::size_t& bytes) {
  Timing t;
  auto start = Clock::now();
  std::vector<tickfx::io::Splat> splats;
  splats.reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const auto q = camera.project(points[i]);
    if (!q) continue;
    splats.push_back({static_cast<float>(q->x), static_cast<float>(q->y),
                      static_cast<float>(q->depth), 1.5f,
                      tickfx::io::viridis(static_cast<double>(i) / points.size())});
  }
  t.project = seconds(start);
  start = Clock::now();
  tickfx::io::SplatImage image(camera.width(), camera.height(), {24, 24, 28});
  image.draw(std::move(splats));
  t.draw = seconds(start);
  start = Clock::now();
  bytes = image.png().size();
  t.png = seconds(start);
  return t;
}

}  // namespace

int main(int argc, char** argv) {
  const bool quick = argc > 1 && std::strcmp(argv[1], "--quick") == 0;
  const std::size_t n = quick ? 100'000 : 1'000'000;
  const int repeats = quick ? 3 : 7;
  std::printf("render_bench: %zu particles in a 6 x 2 x 2 m box to a 1280x720 PNG (%s build)\n", n,
              TICKFX_BENCH_CONFIG);
  std::mt19937 random(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Eigen::Vector3d> points;
  for (std::size_t i = 0; i < n; ++i)
    points.emplace_back(3.0 * u(random), 1.0 + u(random), u(random));
  const auto camera = tickfx::io::PinholeCamera::framing({-3, 0, -1}, {3, 2, 1},
                                                         Eigen::Vector3d::UnitY(), 40.0, 1280, 720);
  const int all = tbb::info::default_concurrency();
  std::vector<std::pair<int, Timing>> results;
  std::size_t bytes = 0;
  for (const int threads : {1, all}) {
    if (threads == all && all == 1 && !results.empty()) break;
    tbb::task_arena arena(threads);
    std::vector<Timing> runs;
    arena.execute([&] {
      renderOnce(points, camera, bytes);  // warm-up: first-touch pages, TBB workers
      for (int r = 0; r < repeats; ++r) runs.push_back(renderOnce(points, camera, bytes));
    });
    std::sort(runs.begin(), runs.end(),
              [](const Timing& a, const Timing& b) { return a.total() < b.total(); });
    results.emplace_back(threads, runs[runs.size() / 2]);
  }
  std::printf("%8s %12s %12s %12s %12s\n", "threads", "project s", "draw s", "png s", "total s");
  for (const auto& [threads, t] : results) {
    std::printf("%8d %12.4f %12.4f %12.4f %12.4f\n", threads, t.project, t.draw, t.png, t.total());
  }
  std::printf("\n");
  const std::string size = n == 1'000'000 ? "1e6" : "1e5";
  for (const auto& [threads, t] : results) {
    std::printf(
        "render %s 1280x720 %d thread%s: %.3f s a frame (project %.3f, draw %.3f, png %.3f; "
        "%.2fx 1 thread; target < 1 s at 1e6; %zu bytes)\n",
        size.c_str(), threads, threads == 1 ? "" : "s", t.total(), t.project, t.draw, t.png,
        results.front().second.total() / t.total(), bytes);
  }
  return 0;
}
