// The guarantee: the state after tick k is bitwise identical whatever frame times drove the
// driver and whatever the thread count.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <memory>
#include <mutex>
#include <set>
#include <thread>

#include "Sanitized.h"
#include "app/DeterminismCheck.h"
#include "app/DifferenceImage.h"
#include "app/FrameTimes.h"
#include "fields/ForceSet.h"
#include "fields/Gravity.h"
#include "fields/LinearDrag.h"
#include "fields/PeriodicWind.h"
#include "io/cache/FrameData.h"
#include "io/effect/EffectBuilder.h"
#include "io/effect/EffectParser.h"
#include "particles/ParticleSystem.h"
#include "particles/StateHash.h"

namespace fs = std::filesystem;

namespace tickfx::app {
namespace {

std::vector<fs::path> sampleEffects() {
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(fs::path(TICKFX_SOURCE_DIR) / "samples")) {
    if (entry.path().extension() == ".toml") files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

io::EffectSettings load(const fs::path& file) {
  const io::LoadResult r = io::loadEffectFile(file);
  EXPECT_TRUE(r.ok()) << file;
  return *r.effect;
}

class EverySample : public ::testing::TestWithParam<fs::path> {};

// A regression guard: every schedule runs the same ticks through the same code, so this fails
// only if the frames leak into a tick (a float time accumulator in the driver does); it cannot
// show a difference between builds or machines (determinism.compilers and the golden hashes do).
// Under the sanitizers, four of the ten schedules: a frame rate that meets the ticks, one that
// falls between them (30000/1001), a jittered host and the recorded frames (test::kSanitized).
TEST_P(EverySample, HashesAt1s2s5sAgreeUnderEveryFrameScheduleRegressionGuard) {
  const io::EffectSettings effect = load(GetParam());
  const std::int64_t rate = effect.simulation.stepRateHz;
  const std::vector<std::int64_t> ticks = {rate, 2 * rate, 5 * rate};
  std::vector<DriveTrace> traces;
  const std::vector<DriveCase> drives = standardDriveCases(5 * kFlicksPerSecond, {1});
  ASSERT_EQ(drives.size(), 10u);
  for (std::size_t k = 0; k < drives.size(); ++k) {
    if (test::kSanitized && k != 0 && k != 3 && k != 6 && k != 9) continue;
    traces.push_back(traceDrive(effect, drives[k], ticks));
    EXPECT_EQ(traces.back().ticks, ticks) << drives[k].label;
    EXPECT_EQ(traces.back().ticksDropped, 0) << drives[k].label;
  }
  const Divergence d = firstDivergence(traces);
  EXPECT_EQ(d.tick, -1) << "runs part at tick " << d.tick
                        << ", first: " << traces[d.runs.empty() ? 0 : d.runs[0]].label;
}

INSTANTIATE_TEST_SUITE_P(Samples, EverySample, ::testing::ValuesIn(sampleEffects()),
                         [](const ::testing::TestParamInfo<fs::path>& p) {
                           return p.param.stem().string();
                         });

// Adds nothing; remembers which threads evaluated forces, to prove the thread count was real.
// With `hold`, its first 200 blocks wait 0.2 ms each until three threads have been seen: on a
// loaded 2-core machine the workers of an 8-thread arena may otherwise not be scheduled before one
// or two threads have done every block (the bits agree either way; the proof would be missing).
class ThreadRecorder final : public ForceModule {
 public:
  explicit ThreadRecorder(bool hold) : hold_(hold) {}
  std::string_view typeName() const override { return "thread_recorder"; }
  void accumulate(const ForceInput&, RowRange, Vec3Rows&) const override {
    bool wait = false;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      threads_.insert(std::this_thread::get_id());
      wait = hold_ && threads_.size() < 3 && ++held_ <= 200;
    }
    if (wait) std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  std::size_t distinctThreads() const { return threads_.size(); }

 private:
  bool hold_;
  mutable std::mutex mutex_;
  mutable std::set<std::thread::id> threads_;
  mutable int held_ = 0;
};

TEST(Threads, OneTwoThreeAndEightThreadsGiveTheSameBitsAfterEveryTick) {
  // TBB keeps its workers to the core count, and a system never raises that process-wide limit:
  // the test, as the host here, does, so that 8 threads really run on a 2-core machine.
  const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 8);
  std::vector<std::vector<std::uint64_t>> traces;
  for (int threads : {1, 2, 3, 8}) {
    SystemSettings settings;
    settings.stepRateHz = 60;
    settings.integrator = "rk4";
    settings.threads = threads;
    settings.seed = 5;
    EmitterSettings e;
    e.shape = BoxShape{Eigen::Vector3d(4.0, 1.0, 4.0)};
    e.bursts = {{0.0, 120000}};  // 15 blocks of rows
    e.rate = 20000.0;
    e.speed = 2.0;
    e.spreadDegrees = 90.0;
    e.lifetime = 0.25;
    e.lifetimeJitter = 0.8;
    ForceSet forces;
    forces.add(std::make_unique<Gravity>());
    PeriodicWind::Settings wind;
    wind.amplitude = 2.0f;
    wind.frequency = 1.5;
    forces.add(std::make_unique<PeriodicWind>(wind));
    forces.add(std::make_unique<LinearDrag>(0.4f));
    auto* recorder =
        static_cast<ThreadRecorder*>(&forces.add(std::make_unique<ThreadRecorder>(threads == 8)));
    ParticleSystem system(settings, {e}, std::move(forces));
    std::vector<std::uint64_t> hashes;
    system.setTickObserver([&](const ParticleSystem& s) { hashes.push_back(stateHash(s.pool())); });
    system.stepTicks(20);
    traces.push_back(hashes);
    if (threads == 8) {
      EXPECT_GT(recorder->distinctThreads(), 2u) << "8 threads asked, fewer ran";
    }
    if (threads == 1) {
      EXPECT_EQ(recorder->distinctThreads(), 1u);
    }
  }
  for (std::size_t i = 1; i < traces.size(); ++i)
    EXPECT_EQ(traces[i], traces[0]) << "thread set " << i;
}

// A frame that two schedules both render shows the same bits: t = 1 s and 2 s at 24, 60 and
// 120 fps; t = 0.2 s at 25 and 50 fps.
TEST(InterpolatedCaches, AFrameTwoSchedulesShareIsBitwiseIdentical) {
  const io::EffectSettings effect = load(fs::path(TICKFX_SOURCE_DIR) / "samples/burst.toml");
  auto frameAt = [&](FrameRate rate, Flicks time) {
    const auto system = io::buildSystem(effect, 1);
    const Flicks frame = frameDuration(rate);
    for (Flicks t = 0; t < time; t += frame) system->advance(frame);
    return io::captureFrame(*system, 0, secondsFromFlicks(time));
  };
  auto expectSame = [](const io::FrameData& a, const io::FrameData& b, const char* what) {
    ASSERT_GT(a.size(), 0u) << what;
    ASSERT_EQ(a.id, b.id) << what;
    for (int c = 0; c < 3; ++c) {
      EXPECT_EQ(std::memcmp(a.position[c].data(), b.position[c].data(), a.size() * sizeof(float)),
                0)
          << what;
      EXPECT_EQ(std::memcmp(a.velocity[c].data(), b.velocity[c].data(), a.size() * sizeof(float)),
                0)
          << what;
    }
    EXPECT_EQ(std::memcmp(a.age.data(), b.age.data(), a.size() * sizeof(float)), 0) << what;
  };
  for (Flicks t : {kFlicksPerSecond, 2 * kFlicksPerSecond}) {
    const io::FrameData at24 = frameAt({24, 1}, t);
    expectSame(at24, frameAt({60, 1}, t), "24 vs 60 fps");
    expectSame(at24, frameAt({120, 1}, t), "24 vs 120 fps");
  }
  // 0.2 s is 24 ticks at 120 Hz plus nothing: and at 25 fps vs 50 fps an α of 0 on both sides.
  expectSame(frameAt({25, 1}, kFlicksPerSecond / 5), frameAt({50, 1}, kFlicksPerSecond / 5),
             "25 vs 50 fps");
}

TEST(FirstDivergence, NamesTheFirstTickAndTheRunsThatDiffer) {
  std::vector<DriveTrace> traces(3);
  for (DriveTrace& t : traces) t.ticks = {1, 2, 3, 4};
  traces[0].hashes = {10, 20, 30, 40};
  traces[1].hashes = {10, 20, 30, 40};
  traces[2].hashes = {10, 20, 31, 41};
  Divergence d = firstDivergence(traces);
  EXPECT_EQ(d.tick, 3);
  EXPECT_EQ(d.runs, std::vector<std::size_t>{2});
  traces[2].hashes = {10, 20, 30, 40};
  EXPECT_EQ(firstDivergence(traces).tick, -1);
  traces[1].ticks.pop_back();  // a run that stopped short parts where it stopped
  traces[1].hashes.pop_back();
  d = firstDivergence(traces);
  EXPECT_EQ(d.tick, 4);
  EXPECT_EQ(d.runs, std::vector<std::size_t>{1});
}

TEST(FirstDivergence, ADifferentSeedIsCaughtAtTheFirstTickWithParticles) {
  io::EffectSettings effect = load(fs::path(TICKFX_SOURCE_DIR) / "samples/fountain.toml");
  const DriveCase drive{"60 fps", app::fixedRateFrames({60, 1}, kFlicksPerSecond / 2), 1};
  std::vector<DriveTrace> traces{traceDrive(effect, drive)};
  effect.simulation.seed += 1;
  traces.push_back(traceDrive(effect, drive));
  const Divergence d = firstDivergence(traces);
  EXPECT_EQ(d.tick, 1) << "the fountain emits in its first tick";
  EXPECT_EQ(d.runs, std::vector<std::size_t>{1});
}

TEST(StateAfterTick, IsTheSameStateWhateverTheFramesAndThreads) {
  const io::EffectSettings effect = load(fs::path(TICKFX_SOURCE_DIR) / "samples/fountain.toml");
  const Flicks half = kFlicksPerSecond / 2;
  const io::FrameData a =
      stateAfterTick(effect, {"24 fps", app::fixedRateFrames({24, 1}, half), 1}, 37);
  const io::FrameData b = stateAfterTick(effect, {"jitter 2", app::jitteredFrames(2, half), 2}, 37);
  ASSERT_GT(a.size(), 100u);  // 2000 particles a second for 37/120 s
  EXPECT_EQ(io::frameHash(a), io::frameHash(b));
  EXPECT_DOUBLE_EQ(a.timeSeconds, 37.0 / 120.0);
  EXPECT_EQ(stateAfterTick(effect, {"24 fps", app::fixedRateFrames({24, 1}, half), 1}, 61).size(),
            0u)
      << "half a second is 60 ticks: there is no tick 61";
}

TEST(DifferenceImage, ColoursEachParticleByTheDistanceToItsTwin) {
  io::EffectSettings effect = load(fs::path(TICKFX_SOURCE_DIR) / "samples/fountain.toml");
  const DriveCase drive{"60 fps", app::fixedRateFrames({60, 1}, kFlicksPerSecond / 2), 1};
  const io::FrameData a = stateAfterTick(effect, drive, 40);
  DifferenceSummary same;
  const preview::SplatImage agreeing = renderDifference(a, a, "'a'", "'b'", 40, 320, 180, &same);
  EXPECT_EQ(same.differing, 0u);
  EXPECT_EQ(same.largest, 0.0);
  // Another seed: the same ids, elsewhere.
  effect.simulation.seed += 1;
  const io::FrameData b = stateAfterTick(effect, drive, 40);
  ASSERT_EQ(b.id, a.id);
  DifferenceSummary parted;
  const preview::SplatImage differing = renderDifference(a, b, "'a'", "'b'", 40, 320, 180, &parted);
  EXPECT_EQ(parted.differing, a.size());
  double largest = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const auto r = static_cast<Eigen::Index>(i);
    largest = std::max(largest, Eigen::Vector3d(a.position.x[r] - b.position.x[r],
                                                a.position.y[r] - b.position.y[r],
                                                a.position.z[r] - b.position.z[r])
                                    .norm());
  }
  EXPECT_EQ(parted.largest, largest);
  EXPECT_GT(largest, 0.01);
  EXPECT_NE(differing.png(), agreeing.png());
  // A particle only one state has counts as differing.
  io::FrameData fewer = a;
  fewer.resize(a.size() - 1, {});
  fewer.id.assign(a.id.begin(), a.id.end() - 1);
  for (int c = 0; c < 3; ++c) fewer.position[c] = a.position[c].head(a.position.x.size() - 1);
  DifferenceSummary one;
  renderDifference(a, fewer, "'a'", "'b'", 40, 64, 36, &one);
  EXPECT_EQ(one.differing, 1u);
  EXPECT_EQ(one.largest, 0.0);
}

}  // namespace
}  // namespace tickfx::app
