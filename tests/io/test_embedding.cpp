// The embedding API as a host uses it: loadEffect() with errors as values, render copies into the
// host's own buffers, and the host's job system running the parallel loops.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <unistd.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "WorkerPool.h"
#include "io/effect/EffectLoader.h"
#include "io/state/Checkpoint.h"
#include "particles/StateHash.h"
#include "particles/TaskExecutor.h"

namespace tickfx {
namespace {

namespace fs = std::filesystem;
const fs::path kSamples = fs::path(TICKFX_SOURCE_DIR) / "samples";

class Embedding : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("tickfx_embedding_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string write(const std::string& name, const std::string& text) const {
    const fs::path p = dir_ / name;
    std::ofstream(p) << text;
    return p.string();
  }
  fs::path dir_;
};

std::vector<std::string> lines(const LoadedEffect& loaded) {
  std::vector<std::string> out;
  for (const io::Diagnostic& d : loaded.diagnostics) out.push_back(d.format());
  return out;
}

constexpr const char* kBall =
    "format_version = 1\n"
    "[simulation]\n"
    "step_rate = 60\n"
    "[[emitters]]\n"
    "bursts = [{ time = 0.0, count = 1 }]\n"
    "speed = 0.0\n"
    "[[forces]]\n"
    "type = \"gravity\"\n"
    "acceleration = [0.0, -9.81, 0.0]\n";

LoadOptions offlineOptions() {
  LoadOptions options;
  options.offline = true;
  return options;
}

LoadOptions lintOptions() {
  LoadOptions options;
  options.lint = true;
  return options;
}

// ---- loadEffect: a system, or the CLI's diagnostics as values --------------------------------

TEST_F(Embedding, LoadsASampleIntoARunningSystem) {
  const LoadedEffect fx = loadEffect(kSamples / "fountain.toml");
  ASSERT_TRUE(fx.ok()) << fx.text();
  EXPECT_TRUE(fx.diagnostics.empty());
  EXPECT_EQ(fx.text(), "");
  ASSERT_TRUE(fx.effect.has_value());
  EXPECT_EQ(fx.effect->output.fps.numerator, 24);
  EXPECT_EQ(fx.system->settings().stepRateHz, 120);
  EXPECT_EQ(fx.system->settings().maxTicksPerFrame, 16);  // a real-time host keeps the cap
  fx.system->advance(frameDuration({24, 1}));
  EXPECT_EQ(fx.system->tickCount(), 5);
  EXPECT_GT(fx.system->pool().size(), 0u);
}

TEST_F(Embedding, OverridesAreAppliedAsTheCommandLineAppliesThem) {
  const LoadedEffect fx =
      loadEffect(kSamples / "fountain.toml", {{"simulation.step_rate", "240"},
                                              {"simulation.integrator", "rk4"},
                                              {"emitters.0.direction", "[1, 0, 0]"}});
  ASSERT_TRUE(fx.ok()) << fx.text();
  EXPECT_EQ(fx.system->settings().stepRateHz, 240);
  EXPECT_EQ(fx.system->settings().integrator, "rk4");
  // The identity `tickfx run --set ...` records in caches and checkpoints: the file and each
  // override as key=value, in order.
  EXPECT_EQ(fx.fingerprint,
            io::effectFileFingerprint(kSamples / "fountain.toml",
                                      {"simulation.step_rate=240", "simulation.integrator=rk4",
                                       "emitters.0.direction=[1, 0, 0]"}));
  EXPECT_NE(fx.fingerprint, loadEffect(kSamples / "fountain.toml").fingerprint);
}

TEST_F(Embedding, ErrorsComeBackAsTheCheckCommandsLines) {
  const std::string file = write("bad.toml", "unknown_key = 1\n" + std::string(kBall));
  const LoadedEffect fx = loadEffect(file, {{"simulation.step_rate", "-5"}});
  EXPECT_FALSE(fx.ok());
  EXPECT_EQ(fx.system, nullptr);
  EXPECT_FALSE(fx.effect.has_value());
  EXPECT_EQ(fx.fingerprint, 0u);
  ASSERT_EQ(lines(fx).size(), 2u) << fx.text();
  EXPECT_EQ(lines(fx)[0],
            file +
                ":1:1: error: unknown_key: unknown key \"unknown_key\" (expected "
                "one of: format_version, simulation, emitters, forces, colliders, output)");
  EXPECT_EQ(lines(fx)[1].rfind("--set simulation.step_rate: error: simulation.step_rate: ", 0), 0u)
      << lines(fx)[1];
  EXPECT_EQ(fx.text(), lines(fx)[0] + "\n" + lines(fx)[1] + "\n");
}

TEST_F(Embedding, AMissingFileOrBrokenTomlIsAValueNotAnException) {
  const LoadedEffect missing = loadEffect(dir_ / "none.toml");
  EXPECT_FALSE(missing.ok());
  EXPECT_EQ(lines(missing), std::vector<std::string>{(dir_ / "none.toml").string() +
                                                     ": error: no such file (expected a readable "
                                                     "effect file)"});
  const std::string broken = write("broken.toml", "[simulation\n");
  const LoadedEffect fx = loadEffect(broken);
  EXPECT_FALSE(fx.ok());
  ASSERT_EQ(fx.diagnostics.size(), 1u);
  EXPECT_EQ(fx.diagnostics[0].line, 1);
  EXPECT_EQ(fx.diagnostics[0].severity, io::Severity::Error);
}

TEST_F(Embedding, AFieldFileThatCannotBeReadIsADiagnosticAtItsKey) {
  const std::string file =
      write("field.toml", std::string(kBall) + "[[forces]]\ntype = \"vector_field\"\nfile = \"" +
                              (dir_ / "none.vdb").string() + "\"\n");
  const LoadedEffect fx = loadEffect(file);
  EXPECT_FALSE(fx.ok());
  EXPECT_TRUE(fx.effect.has_value());  // the file is valid; building it is what failed
  EXPECT_EQ(lines(fx),
            std::vector<std::string>{file + ":12:8: error: forces.1.file: " +
                                     (dir_ / "none.vdb").string() + ": grid 'vel': no such file"});
  // checkEffect() reports it as `tickfx check` does: a warning naming the fix.
  const std::vector<io::Diagnostic> check = checkEffect(file);
  ASSERT_EQ(check.size(), 1u);
  EXPECT_EQ(check[0].severity, io::Severity::Warning);
}

TEST_F(Embedding, OfflineRunsEveryTickAndRealTimeDropsPastTheCap) {
  const Flicks oneSecond = kFlicksPerSecond;
  const LoadedEffect realTime = loadEffect(kSamples / "fountain.toml");
  ASSERT_TRUE(realTime.ok());
  const AdvanceResult dropped = realTime.system->advance(oneSecond);
  EXPECT_EQ(dropped.ticks, 16);
  EXPECT_EQ(dropped.ticksDropped, 120 - 16);
  const LoadedEffect offline = loadEffect(kSamples / "fountain.toml", {}, offlineOptions());
  ASSERT_TRUE(offline.ok());
  const AdvanceResult all = offline.system->advance(oneSecond);
  EXPECT_EQ(all.ticks, 120);
  EXPECT_EQ(all.ticksDropped, 0);
}

TEST_F(Embedding, LintWarningsOnRequest) {
  // Explicit Euler gains energy on any spring: the lint says so for the rope sample.
  const std::vector<SettingOverride> euler = {{"simulation.integrator", "explicit_euler"}};
  const LoadedEffect quiet = loadEffect(kSamples / "rope_swing.toml", euler);
  ASSERT_TRUE(quiet.ok()) << quiet.text();
  EXPECT_TRUE(quiet.diagnostics.empty());
  const LoadedEffect linted = loadEffect(kSamples / "rope_swing.toml", euler, lintOptions());
  ASSERT_TRUE(linted.ok());
  ASSERT_FALSE(linted.diagnostics.empty());
  EXPECT_EQ(linted.diagnostics[0].severity, io::Severity::Warning);
  EXPECT_EQ(lines(linted), [&] {
    std::vector<std::string> out;
    for (const io::Diagnostic& d : checkEffect(kSamples / "rope_swing.toml", euler))
      out.push_back(d.format());
    return out;
  }());
}

// ---- render copies -----------------------------------------------------------------------------

std::uint32_t bitsOf(float f) {
  std::uint32_t u;
  std::memcpy(&u, &f, sizeof u);
  return u;
}

// A fountain between two ticks: 1/24 s frames on a 120 Hz clock put most frames between ticks.
std::unique_ptr<ParticleSystem> fountainBetweenTicks() {
  LoadedEffect fx = loadEffect(kSamples / "fountain.toml", {{"simulation.step_rate", "100"}});
  EXPECT_TRUE(fx.ok()) << fx.text();
  for (int f = 0; f < 13; ++f) fx.system->advance(frameDuration({24, 1}));
  EXPECT_GT(fx.system->alpha(), 0.0f);
  EXPECT_LT(fx.system->alpha(), 1.0f);
  return std::move(fx.system);
}

TEST_F(Embedding, RenderCopiesInEveryLayoutAreTheRenderColumnsBitForBit) {
  const auto system = fountainBetweenTicks();
  const std::size_t n = system->pool().size();
  ASSERT_GT(n, 100u);
  Vec3Column position, velocity;
  FloatColumn age;
  system->renderPositions(position);
  system->renderVelocities(velocity);
  system->renderAges(age);
  // Interpolated, so not the tick's own positions.
  EXPECT_NE(bitsOf(position.y[5]), bitsOf(system->pool().position().y[5]));

  std::vector<float> interleaved(3 * n, -1.0f);
  ASSERT_TRUE(
      system->copyRenderPositions(Vec3Destination::interleaved(interleaved.data(), n)).written);
  struct Vertex {
    float p[3];
    std::uint32_t colour;
    float v[3];
    float age;
  };
  std::vector<Vertex> vertices(n, Vertex{{0, 0, 0}, 0xdeadbeef, {0, 0, 0}, 0});
  const CopyResult p =
      system->copyRenderPositions(Vec3Destination::records(vertices[0].p, sizeof(Vertex), n));
  const CopyResult v =
      system->copyRenderVelocities(Vec3Destination::records(vertices[0].v, sizeof(Vertex), n));
  const CopyResult a =
      system->copyRenderAges(FloatDestination{&vertices[0].age, sizeof(Vertex), n});
  EXPECT_TRUE(p.written && v.written && a.written);
  EXPECT_EQ(p.rows, n);
  std::vector<float> x(n), y(n), z(n);
  system->copyRenderPositions(Vec3Destination::columns(x.data(), y.data(), z.data(), n));
  for (std::size_t i = 0; i < n; ++i) {
    const auto r = static_cast<Eigen::Index>(i);
    for (int c = 0; c < 3; ++c) {
      ASSERT_EQ(bitsOf(interleaved[3 * i + c]), bitsOf(position[c][r])) << i;
      ASSERT_EQ(bitsOf(vertices[i].p[c]), bitsOf(position[c][r])) << i;
      ASSERT_EQ(bitsOf(vertices[i].v[c]), bitsOf(velocity[c][r])) << i;
    }
    ASSERT_EQ(bitsOf(x[i]), bitsOf(position.x[r]));
    ASSERT_EQ(bitsOf(y[i]), bitsOf(position.y[r]));
    ASSERT_EQ(bitsOf(z[i]), bitsOf(position.z[r]));
    ASSERT_EQ(bitsOf(vertices[i].age), bitsOf(age[r]));
    ASSERT_EQ(vertices[i].colour, 0xdeadbeefu) << "a copy wrote outside its fields";
  }
}

TEST_F(Embedding, ACopyIntoTooSmallABufferWritesNothingAndSaysHowManyRows) {
  const auto system = fountainBetweenTicks();
  const std::size_t n = system->pool().size();
  std::vector<float> small(3 * (n - 1), 7.0f);
  const CopyResult r =
      system->copyRenderPositions(Vec3Destination::interleaved(small.data(), n - 1));
  EXPECT_FALSE(r.written);
  EXPECT_EQ(r.rows, n);
  for (float f : small) ASSERT_EQ(f, 7.0f);
  std::vector<std::uint64_t> ids(n - 1, 3);
  EXPECT_FALSE(system->copyIds({ids.data(), sizeof(std::uint64_t), n - 1}).written);
  EXPECT_EQ(ids[0], 3u);
}

// restoreClock() gives back what a saved state needs for its render copies between ticks: the
// velocities at the tick's start (without them, render velocities fall back to the tick's own).
TEST_F(Embedding, RestoreClockGivesBackTheTickStartVelocitiesRenderCopiesUse) {
  const auto saved = fountainBetweenTicks();
  const auto restored = fountainBetweenTicks();
  ASSERT_NE(saved->tickStartVelocities(), nullptr);
  const Vec3Column tickStart = *saved->tickStartVelocities();
  Vec3Column expected, velocity;
  saved->renderVelocities(expected);

  restored->restoreClock(restored->tickCount(), nullptr);
  EXPECT_EQ(restored->tickStartVelocities(), nullptr);
  LoadedEffect atStart = loadEffect(kSamples / "fountain.toml");
  ASSERT_TRUE(atStart.ok()) << atStart.text();
  atStart.system->restoreClock(0, nullptr);
  EXPECT_EQ(atStart.system->tickStartVelocities(), nullptr) << "none at tick 0 either";
  restored->renderVelocities(velocity);
  EXPECT_NE(bitsOf(velocity.y[5]), bitsOf(expected.y[5])) << "the tick's own velocities";

  restored->restoreClock(restored->tickCount(), &tickStart);
  ASSERT_NE(restored->tickStartVelocities(), nullptr);
  restored->renderVelocities(velocity);
  for (int c = 0; c < 3; ++c) {
    for (Eigen::Index i = 0; i < expected.x.size(); ++i) {
      ASSERT_EQ(bitsOf(velocity[c][i]), bitsOf(expected[c][i])) << c << ", row " << i;
    }
  }
}

TEST_F(Embedding, IdsAndNamedColumnsCopyTheCurrentTick) {
  const auto system = fountainBetweenTicks();
  const ParticlePool& pool = system->pool();
  const std::size_t n = pool.size();
  std::vector<std::uint64_t> ids(n);
  ASSERT_TRUE(system->copyIds({ids.data(), sizeof(std::uint64_t), n}).written);
  EXPECT_TRUE(std::equal(ids.begin(), ids.end(), pool.id().begin()));
  EXPECT_EQ(ids.front(), 0u);
  std::vector<float> life(n), mass(n);
  ASSERT_TRUE(system->copyColumn("lifetime", {life.data(), sizeof(float), n})->written);
  ASSERT_TRUE(system->copyColumn("mass", {mass.data(), sizeof(float), n})->written);
  for (std::size_t i = 0; i < n; ++i) {
    ASSERT_EQ(bitsOf(life[i]), bitsOf(pool.lifetime()[static_cast<Eigen::Index>(i)]));
    ASSERT_EQ(mass[i], 1.0f);
  }
  EXPECT_FALSE(system->copyColumn("colour", {life.data(), sizeof(float), n}).has_value());
}

// ---- host executors
// ------------------------------------------------------------------------------

class CountingSerial final : public TaskExecutor {
 public:
  void run(std::size_t count, const std::function<void(std::size_t)>& task) override {
    for (std::size_t i = 0; i < count; ++i) task(i);
    tasks_ += count;
  }
  std::size_t tasks_ = 0;
};

std::string hashAfter(ParticleSystem& system, std::int64_t ticks) {
  system.stepTicks(ticks);
  return hashToHex(stateHash(system.pool()));
}

TEST_F(Embedding, HostExecutorsGiveTheArenasBits) {
  // 8000 particles a second living 2.5 s: past 8192 rows, so the loops split into blocks.
  const std::vector<SettingOverride> big = {{"emitters.0.rate", "8000"}};
  const LoadedEffect arena = loadEffect(kSamples / "fountain.toml", big);
  const LoadedEffect serial = loadEffect(kSamples / "fountain.toml", big);
  const LoadedEffect pooled = loadEffect(kSamples / "fountain.toml", big);
  ASSERT_TRUE(arena.ok() && serial.ok() && pooled.ok());
  CountingSerial one;
  WorkerPool four(4);
  serial.system->setTaskExecutor(&one);
  pooled.system->setTaskExecutor(&four);
  EXPECT_EQ(pooled.system->taskExecutor(), &four);
  const std::int64_t ticks = 3 * 120;
  const std::string expected = hashAfter(*arena.system, ticks);
  EXPECT_EQ(hashAfter(*serial.system, ticks), expected);
  EXPECT_EQ(hashAfter(*pooled.system, ticks), expected);
  EXPECT_GT(arena.system->pool().size(), 2 * std::size_t{8192});
  // The executors really ran the blocks: more than one per loop once past 8192 rows.
  EXPECT_GT(one.tasks_, static_cast<std::size_t>(ticks));
  EXPECT_GT(four.tasksRun(), static_cast<std::size_t>(ticks));
  // Render copies run on the executor too, and give the arena's bits.
  pooled.system->advance(frameDuration({24, 1}) / 2);
  arena.system->advance(frameDuration({24, 1}) / 2);
  Vec3Column a, b;
  arena.system->renderPositions(a);
  pooled.system->renderPositions(b);
  for (int c = 0; c < 3; ++c) EXPECT_TRUE((a[c] == b[c]).all());
  // Back to the system's own arena.
  pooled.system->setTaskExecutor(nullptr);
  const std::size_t before = four.tasksRun();
  pooled.system->step();
  EXPECT_EQ(four.tasksRun(), before);
}

TEST_F(Embedding, ASystemLeavesTbbsProcessWideLimitAlone) {
  // A host's own TBB limit is the host's: 64 threads asked of a 2-core machine do not raise it.
  const std::size_t before =
      tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism);
  LoadOptions many;
  many.threads = 64;
  const LoadedEffect fx = loadEffect(kSamples / "fountain.toml", {}, many);
  ASSERT_TRUE(fx.ok()) << fx.text();
  EXPECT_EQ(fx.system->settings().threads, 64);
  fx.system->stepTicks(2);
  EXPECT_EQ(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism),
            before);
}

}  // namespace
}  // namespace tickfx
