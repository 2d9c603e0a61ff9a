// `tickfx run`, `check` and `study` as processes: exit codes, output, and files written or not.
#include <gtest/gtest.h>

#include <tuple>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>
#include <sstream>
#include <string>

#include "CliTestSupport.h"
#include "DecodedPng.h"
#include "app/preview/FrameRenderer.h"
#include "io/cache/CsvCache.h"
#include "io/cache/PlyCache.h"

namespace fs = std::filesystem;

namespace {

using tickfx::cli_test::readAll;
using tickfx::cli_test::Result;

class Cli : public tickfx::cli_test::CliFixture {
 protected:
  Cli() : CliFixture("tickfx_cli") {}

  // `tickfx ARGS` from the source tree, stdin closed.
  Result run(const std::string& args) const { return runProgram(TICKFX_CLI, args); }
  // "HASH@TICKS" from the two lines --hash prints.
  static std::string hashOf(const Result& r) {
    const std::size_t at = r.out.find("state-hash: ");
    const std::size_t ticks = r.out.find("\nticks: ", at);
    if (at == std::string::npos || ticks != at + 12 + 16) return "no hash in: " + r.out + r.err;
    const std::string hash = r.out.substr(at + 12, 16);
    if (hash.find_first_not_of("0123456789abcdef") != std::string::npos) return "bad hash: " + hash;
    return hash + "@" + r.out.substr(ticks + 8, r.out.find('\n', ticks + 1) - ticks - 8);
  }
};

TEST_F(Cli, HelpOnEveryCommandExitsZero) {
  for (const char* c : {"--help", "run --help", "check --help", "study --help"}) {
    const Result r = run(c);
    EXPECT_EQ(r.exit, 0) << c;
    EXPECT_NE(r.out.find("usage: tickfx"), std::string::npos) << c;
  }
  EXPECT_EQ(run("").exit, 2);
  EXPECT_EQ(run("explode").exit, 2);
}

TEST_F(Cli, RunWritesOneCachePerFrameAndReportsTheHash) {
  const Result r = run("run samples/fountain.toml --seconds 1 --fps 24 --format csv,ply --out " +
                       path("c") + " --hash");
  ASSERT_EQ(r.exit, 0) << r.err;
  EXPECT_TRUE(fs::exists(path("c/frame_0024.csv")));
  EXPECT_TRUE(fs::exists(path("c/frame_0024.ply")));
  EXPECT_FALSE(fs::exists(path("c/frame_0025.csv")));
  EXPECT_NE(r.out.find("samples/fountain.toml: 24 frames at 24 fps, 1 s simulated (120 ticks at "
                       "120 Hz, semi_implicit_euler)"),
            std::string::npos)
      << r.out;
  EXPECT_EQ(r.err.find('\r'), std::string::npos)
      << "no progress line when stderr is not a terminal";
  // 1 s at 120 Hz is 120 ticks, and a second run gives the same bits.
  EXPECT_EQ(hashOf(r).substr(17), "120");
  EXPECT_EQ(hashOf(run("run samples/fountain.toml --seconds 1 --fps 24 --format none --hash")),
            hashOf(r));
}

TEST_F(Cli, CsvAndPlyCachesHoldTheSameBits) {
  ASSERT_EQ(
      run("run samples/burst.toml --frames 12 --fps 24 --format csv,ply --out " + path("c")).exit,
      0);
  const tickfx::io::FrameData csv = tickfx::io::readCsvCache(path("c/frame_0012.csv"));
  const tickfx::io::FrameData ply = tickfx::io::readPlyCache(path("c/frame_0012.ply"));
  ASSERT_GT(csv.size(), 0u);
  ASSERT_EQ(csv.size(), ply.size());
  EXPECT_EQ(csv.id, ply.id);
  EXPECT_EQ(ply.frame, 12);
  for (int c = 0; c < 3; ++c) {
    EXPECT_TRUE((csv.position[c] == ply.position[c]).all());
    EXPECT_TRUE((csv.velocity[c] == ply.velocity[c]).all());
  }
  EXPECT_TRUE((csv.age == ply.age).all());
  EXPECT_TRUE((csv.life == ply.life).all());
  EXPECT_EQ(readAll(path("c/frame_0012.ply")).rfind("ply\nformat binary_little_endian 1.0\n", 0),
            0u);
}

TEST_F(Cli, OscillatorDumpAgreesWithMinusCosT) {
  // Velocity Verlet at 60 Hz: phase error ω³dt²t/24 ≈ 2.3e-4 rad after 20 s.
  for (const auto& [integrator, tolerance] :
       std::vector<std::pair<std::string, double>>{{"velocity_verlet", 3e-4}, {"rk4", 2e-5}}) {
    const std::string dump = path("dump_" + integrator + ".csv");
    const Result r =
        run("run samples/oscillator.toml --seconds 20 --format none --set simulation.integrator=" +
            integrator + " --dump " + dump);
    ASSERT_EQ(r.exit, 0) << r.err;
    std::istringstream rows(readAll(dump));
    std::string header, row;
    std::getline(rows, header);
    std::getline(rows, row);
    EXPECT_EQ(header, "id,px,py,pz,vx,vy,vz,age");
    double id, px, py, pz, vx, vy, vz, age;
    ASSERT_EQ(std::sscanf(row.c_str(), "%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf", &id, &px, &py, &pz, &vx,
                          &vy, &vz, &age),
              8);
    EXPECT_NEAR(px, -std::cos(20.0), tolerance) << integrator;
    EXPECT_NEAR(vx, std::sin(20.0), tolerance) << integrator;
    EXPECT_EQ(age, 20.0);
  }
}

// A regression guard: every frame source runs the same ticks through the same code; this fails
// only if the frames leak into a tick.
TEST_F(Cli, JitteredAndRecordedFrameTimesReachTheSameTickStateRegressionGuard) {
  const std::string reference =
      hashOf(run("run samples/fountain.toml --seconds 2 --fps 60 --format none --hash"));
  EXPECT_EQ(hashOf(run("run samples/fountain.toml --seconds 2 --jitter 7 --format none --hash")),
            reference);
  EXPECT_EQ(
      hashOf(run("run samples/fountain.toml --seconds 2 --fps 30000/1001 --format none --hash")),
      reference);
  std::string times;
  for (int i = 0; i < 40; ++i) times += (i % 2 == 0 ? "0.03\n" : "0.07\n");  // 40 frames, 2 s
  const std::string file = writeFile("times.txt", "# alternating frames\n" + times);
  EXPECT_EQ(
      hashOf(run("run samples/fountain.toml --frame-times " + file + " --format none --hash")),
      reference);
}

TEST_F(Cli, CheckWarnsAboutTheAliasedWindWithTheStepRateNeeded) {
  const Result bad = run("check samples/wind_aliasing.toml");
  EXPECT_EQ(bad.exit, 0);
  EXPECT_NE(bad.err.find("samples/wind_aliasing.toml:"), std::string::npos) << bad.err;
  EXPECT_NE(bad.err.find("warning: forces.0.frequency:"), std::string::npos) << bad.err;
  EXPECT_NE(bad.err.find("use a step_rate of at least 33 Hz"), std::string::npos) << bad.err;
  const Result good = run("check samples/wind_aliasing_fixed.toml");
  EXPECT_EQ(good.exit, 0);
  EXPECT_EQ(good.err, "");
  EXPECT_NE(good.out.find("ok, 0 warning(s)"), std::string::npos);
}

TEST_F(Cli, EffectErrorsExitTwoAndWriteNothing) {
  const std::string effect = writeFile("bad.toml",
                                       "format_version = 1\n"
                                       "[simulation]\n"
                                       "step_rate = 0\n"
                                       "integrator = \"rk5\"\n"
                                       "[[emitters]]\n"
                                       "rate = 10.0\n");
  for (const std::string command : {"run", "check"}) {
    const Result r =
        run(command + " " + effect + (command == "run" ? " --out " + path("never") : ""));
    EXPECT_EQ(r.exit, 2) << command;
    EXPECT_NE(r.err.find(effect + ":3:13: error: simulation.step_rate:"), std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find(effect + ":4:14: error: simulation.integrator:"), std::string::npos)
        << r.err;
    EXPECT_FALSE(fs::exists(path("never")));
  }
  const Result set =
      run("run samples/fountain.toml --set simulation.step_rate=-5 --out " + path("never"));
  EXPECT_EQ(set.exit, 2);
  EXPECT_NE(set.err.find("--set simulation.step_rate"), std::string::npos) << set.err;
  EXPECT_FALSE(fs::exists(path("never")));
}

TEST_F(Cli, UsageErrorsExitTwoAndWriteNothing) {
  const std::string out = " --out " + path("never");
  for (const std::string args :
       {"run samples/fountain.toml --seconds 1 --frames 3", "run samples/fountain.toml --fps 0",
        "run samples/fountain.toml --fps 7/0", "run samples/fountain.toml --format gif",
        "run samples/fountain.toml --bogus", "run samples/fountain.toml --seconds nan",
        "run samples/fountain.toml --jitter 3 --fps 60", "run", "check", "study extra"}) {
    const Result r = run(args + out);
    EXPECT_EQ(r.exit, 2) << args << "\n" << r.err;
    EXPECT_FALSE(r.err.empty()) << args;
    EXPECT_FALSE(fs::exists(path("never"))) << args;
  }
  const Result missing = run("run samples/no_such_effect.toml" + out);
  EXPECT_EQ(missing.exit, 2);
  EXPECT_NE(missing.err.find("samples/no_such_effect.toml"), std::string::npos);
  const Result badTimes =
      run("run samples/fountain.toml --frame-times " + writeFile("t.txt", "0.1\nsoon\n") + out);
  EXPECT_EQ(badTimes.exit, 2);
  EXPECT_NE(badTimes.err.find("t.txt:2: error: 'soon' is not a frame duration"), std::string::npos)
      << badTimes.err;
}

TEST_F(Cli, FailureAtRunTimeExitsOne) {
  // The second frame's cache cannot be written (a folder holds its name): found only then.
  fs::create_directories(path("c/frame_0002.csv"));
  const Result r = run("run samples/fountain.toml --frames 2 --out " + path("c"));
  EXPECT_EQ(r.exit, 1) << r.err;
  EXPECT_NE(r.err.find("error:"), std::string::npos);
  EXPECT_TRUE(fs::exists(path("c/frame_0001.csv")));
}

// Regression (issue 12, item 1): the flag under explicit Euler at 30 Hz (lint: x712 energy per
// step) was written for 10 s as rows of "-nan" with exit 0. Its state is first non-finite at tick
// 19 (0.6333 s); at 60 fps frame 37 (0.6167 s) already needs tick 19 to interpolate, so frames
// 1–36 are the ones before it.
TEST_F(Cli, AnEffectThatBlowsUpStopsAtTheTickWithItsLikelyCauseAfterTheFramesBeforeIt) {
  const std::string unstable =
      "run samples/flag.toml --set simulation.step_rate=30 --set simulation.integrator="
      "explicit_euler --seconds 10 --format csv --out ";
  const Result stop = run(unstable + path("stop"));
  EXPECT_EQ(stop.exit, 1);
  EXPECT_NE(stop.err.find("samples/flag.toml: error: tick 19 (t = 0.633333333 s): 58 particles "
                          "have a non-finite position or velocity (ids 10, 11, 12, 13, 14, 15, "
                          "16, 17, ...); the run stops there (simulation.nonfinite = \"stop\"; "
                          "\"kill\" removes such particles instead)\n"
                          "likely cause: samples/flag.toml:24:13: warning: emitters.0.stiffness: "
                          "explicit_euler adds energy to this cloth's springs every step"),
            std::string::npos)
      << stop.err;
  EXPECT_NE(stop.err.find("caches written: " + path("stop") + " (frame_0001 to frame_0036)"),
            std::string::npos)
      << stop.err;
  EXPECT_TRUE(fs::exists(path("stop/frame_0036.csv")));
  EXPECT_FALSE(fs::exists(path("stop/frame_0037.csv")));
  const tickfx::io::FrameData last = tickfx::io::readCsvCache(path("stop/frame_0036.csv"));
  EXPECT_EQ(last.size(), 160u);
  for (int c = 0; c < 3; ++c) {
    EXPECT_TRUE(last.position[c].allFinite());
    EXPECT_TRUE(last.velocity[c].allFinite());
  }

  // "kill": the run goes on without them, and says how many went.
  const Result kill = run(unstable + path("kill") + " --set simulation.nonfinite=kill");
  EXPECT_EQ(kill.exit, 0) << kill.err;
  EXPECT_NE(kill.out.find("particles alive: 10 (emitted 160, refused by max_particles: 0)\n"
                          "removed for a non-finite position or velocity: 150\n"),
            std::string::npos)
      << kill.out;
  EXPECT_EQ(readAll(path("kill/frame_0600.csv")).find("nan"), std::string::npos);

  // "keep": today's values, in the one documented spelling (never printf's "-nan").
  const Result keep = run(unstable + path("keep") + " --set simulation.nonfinite=keep");
  EXPECT_EQ(keep.exit, 0) << keep.err;
  const std::string frame = readAll(path("keep/frame_0600.csv"));
  EXPECT_NE(frame.find(",nan"), std::string::npos);
  EXPECT_EQ(frame.find("-nan"), std::string::npos);
}

// Regression (issue 10, item 15): two identical runs wrote VDB files that differed in about 30
// bytes (OpenVDB's random file UUID). Every format is now the same bytes for the same run; a
// VDB file's UUID comes from the effect, its seed and the frame.
TEST_F(Cli, IdenticalRunsWriteIdenticalBytesInEveryFormat) {
  const std::string run1 = "run samples/burst.toml --frames 3 --format csv,ply,vdb --out ";
  ASSERT_EQ(run(run1 + path("a")).exit, 0);
  ASSERT_EQ(run(run1 + path("b")).exit, 0);
  ASSERT_EQ(run(run1 + path("s") + " --set simulation.seed=7").exit, 0);
  const auto bytes = [&](const std::string& file) {
    std::ifstream in(path(file), std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  };
  for (const char* f : {"frame_0001.csv", "frame_0002.ply", "frame_0003.vdb", "frame_0001.vdb"}) {
    const std::string a = bytes(std::string("a/") + f);
    ASSERT_GT(a.size(), 100u) << f;
    EXPECT_TRUE(a == bytes(std::string("b/") + f)) << f << " differs between identical runs";
  }
  const auto uuid = [&](const std::string& file) { return bytes(file).substr(21, 36); };
  EXPECT_EQ(uuid("a/frame_0001.vdb")[14], '8') << uuid("a/frame_0001.vdb");
  EXPECT_NE(uuid("a/frame_0001.vdb"), uuid("a/frame_0002.vdb"));
  EXPECT_NE(uuid("a/frame_0001.vdb"), uuid("s/frame_0001.vdb"));
}

// Issue 16: writers format in parallel blocks and a background thread writes frame f while
// frame f + 1 simulates. 70 000 particles make several blocks of every writer (CSV 16 384 rows,
// PLY 32 768, VDB placement 16 384), so a block boundary or the writer thread that changed a byte
// would show here.
TEST_F(Cli, CachesHaveTheSameBytesOnAnyThreadCountAndWithOrWithoutTheBackgroundWriter) {
  const std::string effect = writeFile("big.toml", R"(format_version = 1
[simulation]
step_rate = 120
seed = 9
max_particles = 100000
[[emitters]]
shape = "box"
size = [40.0, 10.0, 40.0]
bursts = [{ time = 0.0, count = 70000 }]
speed = 3.0
spread = 60.0
lifetime = 2.0
lifetime_jitter = 0.5
[[forces]]
type = "gravity"
[output]
fps = 24
)");
  const std::string common = "run " + effect + " --frames 3 --format csv,ply,vdb --out ";
  const Result one = run(common + path("t1") + " --threads 1");
  ASSERT_EQ(one.exit, 0) << one.err;
  // The summary splits the wall time between simulating and writing.
  EXPECT_TRUE(std::regex_search(one.out, std::regex("\nwall time: [0-9.]+ s \\(simulating [0-9.]+ "
                                                    "s, writing caches [0-9.]+ s, overlapped "
                                                    "[0-9.]+ s\\)\n")))
      << one.out;
  ASSERT_EQ(run(common + path("t2") + " --threads 2").exit, 0);
  const Result inline2 = run(common + path("n2") + " --threads 2 --no-overlap");
  ASSERT_EQ(inline2.exit, 0) << inline2.err;
  EXPECT_NE(inline2.out.find("not overlapped (--no-overlap): 0.000 s)"), std::string::npos)
      << inline2.out;
  const std::string sized = " --vdb-compression blosc --vdb-positions fixed16 --format vdb";
  ASSERT_EQ(run(common + path("s1") + " --threads 1" + sized).exit, 0);
  ASSERT_EQ(run(common + path("s2") + " --threads 2" + sized).exit, 0);
  for (const char* f : {"frame_0001", "frame_0002", "frame_0003"}) {
    for (const char* ext : {".csv", ".ply", ".vdb"}) {
      const std::string name = std::string(f) + ext;
      const std::string bytes = readAll(path("t1/" + name));
      ASSERT_GT(bytes.size(), 70000u * 12) << name;
      EXPECT_TRUE(bytes == readAll(path("t2/" + name))) << name << ": 1 and 2 threads differ";
      EXPECT_TRUE(bytes == readAll(path("n2/" + name))) << name << ": --no-overlap differs";
    }
    const std::string vdb = std::string(f) + ".vdb";
    const std::string small = readAll(path("s1/" + vdb));
    EXPECT_TRUE(small == readAll(path("s2/" + vdb))) << vdb << " (blosc, fixed16) differs";
    // Smaller, and not by the positions alone (6 of 48 bytes a point).
    EXPECT_LT(small.size(), readAll(path("t1/" + vdb)).size() * 3 / 4) << vdb;
  }
}

TEST_F(Cli, VdbOptionsOfAnotherNameAreUsageErrors) {
  const std::string out = " --out " + path("never");
  const Result zip = run("run samples/fountain.toml --vdb-compression zip" + out);
  EXPECT_EQ(zip.exit, 2);
  EXPECT_NE(zip.err.find("run: --vdb-compression: unknown value 'zip' (expected none or blosc)"),
            std::string::npos)
      << zip.err;
  const Result half = run("run samples/fountain.toml --vdb-positions half" + out);
  EXPECT_EQ(half.exit, 2);
  EXPECT_NE(half.err.find("run: --vdb-positions: unknown value 'half' (expected exact or fixed16)"),
            std::string::npos)
      << half.err;
  EXPECT_FALSE(fs::exists(path("never")));
}

// ---- issue 10: what a run simulates and shows ------------------------------------------------

// Regression (item 0): the cap (max_ticks_per_frame = 16) dropped 1232 of 2000 ticks of an
// offline run and the summary still said 2 s. An offline run now runs every tick its frames
// cover: the same state as frames that never reach the cap.
TEST_F(Cli, AnOfflineRunSimulatesEveryTickItsFramesCover) {
  const std::string effect =
      "run samples/fountain.toml --set simulation.step_rate=1000 --seconds 2 "
      "--format none --hash";
  const Result at24 = run(effect + " --fps 24");
  ASSERT_EQ(at24.exit, 0) << at24.err;
  EXPECT_NE(at24.out.find("48 frames at 24 fps, 2 s simulated (2000 ticks at 1000 Hz"),
            std::string::npos)
      << at24.out;
  EXPECT_EQ(hashOf(at24).substr(17), "2000");
  EXPECT_EQ(hashOf(at24), hashOf(run(effect + " --fps 250")));  // 4 ticks a frame
  EXPECT_EQ(hashOf(at24), hashOf(run(effect + " --fps 2")));    // 500 ticks a frame
  // `check` names what a real-time host at the output's 24 fps would drop.
  const Result check = run("check samples/fountain.toml --set simulation.step_rate=1000");
  EXPECT_EQ(check.exit, 0);
  EXPECT_NE(check.err.find(
                "warning: simulation.max_ticks_per_frame: a real-time host advancing at the "
                "output's 24 fps needs up to 42 ticks a frame at 1000 Hz, more than "
                "max_ticks_per_frame = 16, and would drop ticks (`tickfx run` runs them all; use a "
                "max_ticks_per_frame of at least 42 or a step_rate of at most 384 Hz)"),
            std::string::npos)
      << check.err;
  EXPECT_NE(check.out.find("ok, 1 warning(s)"), std::string::npos) << check.out;
}

// Regression (item 3): --fps alone replayed the file's frame count at the new rate (--fps 60
// simulated 2 s of the fountain's 5, --fps 1 simulated 120 s).
TEST_F(Cli, FpsAloneKeepsTheEffectsLength) {
  for (const auto& [fps, frames] : std::vector<std::pair<std::string, std::string>>{
           {"60", "300"}, {"1", "5"}, {"30000/1001", "150"}, {"24", "120"}}) {
    const Result r = run("run samples/fountain.toml --format none --hash --fps " + fps);
    ASSERT_EQ(r.exit, 0) << r.err;
    EXPECT_NE(r.out.find(": " + frames + " frames at " + fps + " fps, 5 s simulated"),
              std::string::npos)
        << r.out;
    EXPECT_EQ(hashOf(r).substr(17), "600") << fps << " fps: 5 s at 120 Hz";
  }
}

// Regression (item 2): frame 1 at 50 fps held the state of tick 2 (x = 0.01167 m) where the
// particle is at 0.02 m, and at 24 fps its position was a tick older than its age. The dump, like
// every cache, shows the state at the frame's own time.
TEST_F(Cli, ADumpShowsTheStateAtTheEndTime) {
  const std::string effect =
      writeFile("line.toml",
                "format_version = 1\n[simulation]\nstep_rate = 120\n[[emitters]]\n"
                "bursts = [{ time = 0.0, count = 1 }]\ndirection = [1, 0, 0]\nspeed = 1.0\n");
  for (const auto& [fps, seconds, x] : std::vector<std::tuple<std::string, std::string, float>>{
           {"50", "0.02", 0.02f}, {"24", "0.041666666666666667", 1.0f / 24.0f}}) {
    const Result r = run("run " + effect + " --format none --fps " + fps + " --seconds " + seconds +
                         " --dump " + path("d.csv"));
    ASSERT_EQ(r.exit, 0) << r.err;
    std::ifstream in(path("d.csv"));
    std::string header, row;
    std::getline(in, header);
    std::getline(in, row);
    float px = 0, age = 0;
    ASSERT_EQ(std::sscanf(row.c_str(), "0,%g,%*g,%*g,%*g,%*g,%*g,%g", &px, &age), 2) << row;
    EXPECT_NEAR(px, x, 2e-7f) << fps << " fps";
    EXPECT_NEAR(age, x, 2e-7f) << "position and age at one time, " << fps << " fps";
  }
}

// Regressions (items 10 and 11): output.seconds = 10⁹ built the whole list of frames first (192
// GB), and an unwritable --dump was found after every cache had been written. Now every output path
// is checked before the first tick, and frames are made as they are needed.
TEST_F(Cli, OutputPathsAreCheckedBeforeTheFirstTick) {
  const Result dump = run("run samples/fountain.toml --set output.seconds=1e9 --out " + path("c") +
                          " --dump " + path("no/such/dir/d.csv"));
  EXPECT_EQ(dump.exit, 2);
  EXPECT_NE(dump.err.find(path("no/such/dir/d.csv") + ": error: cannot write (no directory " +
                          path("no/such/dir") + ")"),
            std::string::npos)
      << dump.err;
  EXPECT_FALSE(fs::exists(path("c/frame_0001.csv"))) << "nothing written";
  const Result trace = run("run samples/fountain.toml --frames 3 --out " + path("c") + " --trace " +
                           path("c"));  // a folder
  EXPECT_EQ(trace.exit, 2);
  EXPECT_NE(trace.err.find(path("c") + ": error: cannot write (it is a directory)"),
            std::string::npos)
      << trace.err;
  EXPECT_FALSE(fs::exists(path("c/frame_0001.csv")));
}

// Regression (item 12): --threads stopped at 256 and --seconds at 10⁶ where effect files allow
// 1024 threads and 10⁹ s; a resumed run's summary named frames it did not write.
TEST_F(Cli, CommandLineLimitsAgreeWithTheEffectFile) {
  const Result threads = run("run samples/fountain.toml --threads 1025 --format none");
  EXPECT_EQ(threads.exit, 2);
  EXPECT_NE(threads.err.find("run: --threads: '1025' is not a whole number in [0, 1024]"),
            std::string::npos)
      << threads.err;
  const Result seconds = run("run samples/fountain.toml --seconds 2e9 --format none");
  EXPECT_EQ(seconds.exit, 2);
  EXPECT_NE(seconds.err.find("run: --seconds: '2e9' is not a number in [0, 1e+09]"),
            std::string::npos)
      << seconds.err;
  ASSERT_EQ(run("run samples/smoke_drift.toml --frames 12 --format none --checkpoint-every 6 "
                "--checkpoint-dir " +
                path("ck"))
                .exit,
            0);
  const Result resumed = run("run samples/smoke_drift.toml --frames 12 --format csv --out " +
                             path("c") + " --resume " + path("ck/checkpoint_000006.tfxc"));
  ASSERT_EQ(resumed.exit, 0) << resumed.err;
  EXPECT_NE(resumed.out.find("(frame_0007 to frame_0012)"), std::string::npos) << resumed.out;
  EXPECT_FALSE(fs::exists(path("c/frame_0006.csv")));
}

TEST_F(Cli, DeterminismPrintsTheTableAndAVerdict) {
  const Result r = run("determinism samples/fountain.toml --seconds 1 --threads 1,2");
  EXPECT_EQ(r.exit, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("30000/1001 fps"), std::string::npos);
  EXPECT_NE(r.out.find("jitter 3"), std::string::npos);
  EXPECT_NE(r.out.find("verdict: all 12 runs agree bit for bit after every one of 120 ticks"),
            std::string::npos)
      << r.out;
  // The same hash as a plain run of the same length.
  const std::string plain =
      hashOf(run("run samples/fountain.toml --seconds 1 --format none --hash"));
  EXPECT_NE(r.out.find("(state-hash " + plain.substr(0, 16) + ")"), std::string::npos) << r.out;
  EXPECT_EQ(run("determinism samples/fountain.toml --threads 0").exit, 2);
}

TEST_F(Cli, DeterminismWritesNoDifferenceImageWhenTheRunsAgree) {
  const std::string args = "determinism samples/fountain.toml --seconds 0.1 --threads 1,2 ";
  const Result r = run(args + "--diff-image " + path("diff.png"));
  EXPECT_EQ(r.exit, 0) << r.err;
  EXPECT_NE(r.out.find("\nno difference image: the runs agree\n"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(path("diff.png")));
  // A place it could not be written is refused before anything runs.
  const Result bad = run(args + "--diff-image " + path("no/diff.png"));
  EXPECT_EQ(bad.exit, 2);
  EXPECT_EQ(bad.err,
            path("no/diff.png") + ": error: cannot write (no directory " + path("no") + ")\n");
  EXPECT_EQ(bad.out, "");
  EXPECT_EQ(run("determinism samples/fountain.toml --compare x.log --diff-image d.png").err,
            "tickfx determinism: --diff-image does not go with --record or --compare\n");
}

// A regression guard, as above, tick by tick; the trace's own format is checked for real.
TEST_F(Cli, TracesOfTwoFrameRatesAreIdenticalTickForTickRegressionGuard) {
  ASSERT_EQ(
      run("run samples/burst.toml --seconds 2 --fps 24 --format none --trace " + path("a.csv"))
          .exit,
      0);
  ASSERT_EQ(
      run("run samples/burst.toml --seconds 2 --jitter 5 --format none --trace " + path("b.csv"))
          .exit,
      0);
  const std::string a = readAll(path("a.csv"));
  EXPECT_EQ(a.rfind("tick,state_hash\n1,", 0), 0u) << a.substr(0, 40);
  EXPECT_NE(a.find("\n240,"), std::string::npos) << "2 s at 120 Hz";
  EXPECT_EQ(a, readAll(path("b.csv")));
}

TEST_F(Cli, AResumedRunReachesTheUninterruptedHash) {
  const std::string args = "run samples/smoke_drift.toml --seconds 3 --fps 24 --format none --hash";
  const Result whole = run(args + " --checkpoint-every 20 --checkpoint-dir " + path("ck"));
  ASSERT_EQ(whole.exit, 0) << whole.err;
  for (const char* f :
       {"checkpoint_000020.tfxc", "checkpoint_000040.tfxc", "checkpoint_000060.tfxc"}) {
    EXPECT_TRUE(fs::exists(path(std::string("ck/") + f))) << f;
  }
  EXPECT_FALSE(fs::exists(path("ck/checkpoint_000080.tfxc")));
  for (const char* from : {"ck/checkpoint_000020.tfxc", "ck/checkpoint_000060.tfxc"}) {
    const Result resumed = run(args + " --resume " + path(from));
    ASSERT_EQ(resumed.exit, 0) << resumed.err;
    EXPECT_EQ(hashOf(resumed), hashOf(whole)) << from;
  }
  // The caches of a resumed run carry on with the frame numbers of the uninterrupted one.
  ASSERT_EQ(run("run samples/smoke_drift.toml --seconds 3 --fps 24 --format csv --out " +
                path("c") + " --resume " + path("ck/checkpoint_000060.tfxc"))
                .exit,
            0);
  EXPECT_FALSE(fs::exists(path("c/frame_0060.csv")));
  EXPECT_TRUE(fs::exists(path("c/frame_0061.csv")));
  EXPECT_TRUE(fs::exists(path("c/frame_0072.csv")));
}

TEST_F(Cli, BadCheckpointsAreRefusedAndNothingIsWritten) {
  ASSERT_EQ(run("run samples/burst.toml --seconds 1 --fps 24 --format none --checkpoint-every 12 "
                "--checkpoint-dir " +
                path("ck"))
                .exit,
            0);
  const std::string good = path("ck/checkpoint_000012.tfxc");
  const std::string bytes = readAll(good);
  std::string flipped = bytes;
  flipped[bytes.size() / 2] = static_cast<char>(flipped[bytes.size() / 2] ^ 0x10);
  const std::string corrupted = writeFile("corrupted.tfxc", flipped);
  const std::string truncated = writeFile("truncated.tfxc", bytes.substr(0, bytes.size() - 1));
  const std::string out = " --format csv --out " + path("never");
  struct Case {
    std::string args, message;
  };
  for (const Case& c : std::vector<Case>{
           {"run samples/burst.toml --seconds 1 --fps 24 --resume " + corrupted,
            corrupted + ": error: checksum mismatch"},
           {"run samples/burst.toml --seconds 1 --fps 24 --resume " + truncated,
            truncated + ": error: checkpoint is truncated (expected " +
                std::to_string(bytes.size()) + " bytes, found " + std::to_string(bytes.size() - 1) +
                ")"},
           {"run samples/fountain.toml --seconds 1 --fps 24 --resume " + good,
            good + ": error: checkpoint was written for another effect"},
           {"run samples/burst.toml --seconds 1 --fps 24 --set simulation.seed=8 --resume " + good,
            good + ": error: checkpoint was written for another effect"},
           {"run samples/burst.toml --seconds 1 --fps 30 --resume " + good,
            good + ": error: the checkpoint is at frame 12 (0.5 s) but this run's frame 12 ends at "
                   "0.4 s"},
           {"run samples/burst.toml --seconds 1 --fps 24 --resume " + path("missing.tfxc"),
            path("missing.tfxc")}}) {
    const Result r = run(c.args + out);
    EXPECT_EQ(r.exit, 2) << c.args << "\n" << r.err;
    EXPECT_EQ(r.err.rfind(c.message, 0), 0u) << r.err;
    EXPECT_FALSE(fs::exists(path("never"))) << c.args;
  }
}

TEST_F(Cli, StudyWritesOneCsvPerExperiment) {
  const Result r = run("study --out " + path("study"));
  ASSERT_EQ(r.exit, 0) << r.err;
  for (const char* name : {"constant_acceleration.csv", "oscillator.csv", "wind.csv"}) {
    EXPECT_TRUE(fs::exists(path(std::string("study/") + name))) << name;
  }
  // Explicit Euler at dt = 1/20 s lags the exact fall by |a|·dt·T/2 = 2.4525 m after 10 s (less
  // the float round-off of 200 steps at |p| up to 490 m).
  const std::string csv = readAll(path("study/constant_acceleration.csv"));
  const std::size_t row = csv.find("\nexplicit_euler,0.05,20,10,");
  ASSERT_NE(row, std::string::npos) << csv;
  const double error = std::stod(csv.substr(csv.rfind(',', csv.find('\n', row + 1)) + 1));
  EXPECT_NEAR(error, 2.4525, 2e-3);
}

// Width and height from a PNG's IHDR chunk; {0, 0} for anything that does not start as a PNG.
std::pair<std::uint32_t, std::uint32_t> pngSize(const std::string& bytes) {
  if (bytes.size() < 24 || bytes.compare(0, 8, "\x89PNG\r\n\x1a\n") != 0 ||
      bytes.compare(12, 4, "IHDR") != 0) {
    return {0, 0};
  }
  const auto be32 = [&](std::size_t at) {
    std::uint32_t v = 0;
    for (std::size_t i = 0; i < 4; ++i) v = v << 8 | static_cast<unsigned char>(bytes[at + i]);
    return v;
  };
  return {be32(16), be32(20)};
}

TEST_F(Cli, StudyPlotsDrawTheFiguresFromEveryTickOfTheRuns) {
  const Result r = run("study --out " + path("study") + " --plots " + path("plots"));
  ASSERT_EQ(r.exit, 0) << r.err;
  // Figure sizes at 100 dpi: 5 step rates of two panels, 2 oscillator rates of three, one row.
  const std::vector<std::tuple<const char*, std::uint32_t, std::uint32_t>> figures = {
      {"constant_acceleration.png", 1200, 1600},
      {"oscillator.png", 1500, 840},
      {"wind.png", 1300, 450}};
  for (const auto& [name, width, height] : figures) {
    const auto size = pngSize(readAll(path(std::string("plots/") + name)));
    EXPECT_EQ(size.first, width) << name;
    EXPECT_EQ(size.second, height) << name;
    EXPECT_NE(r.out.find("wrote " + path(std::string("plots/") + name)), std::string::npos)
        << r.out;
  }
  EXPECT_FALSE(fs::exists(path("plots/wind.png.partial.png")));
  // Every tick from the start: explicit Euler's first tick at 20 Hz has not moved (p += v·dt with
  // v = 0) and lags the exact fall by 9.81 · 0.05² / 2 m.
  const std::string series = readAll(path("plots/series_constant_acceleration.csv"));
  EXPECT_EQ(series.rfind("integrator,step_rate_hz,t,position,exact,error\n", 0), 0u);
  EXPECT_NE(series.find("\nexplicit_euler,20,0,0,-0,0\n"), std::string::npos);  // -½·g·0²
  EXPECT_NE(series.find("\nexplicit_euler,20,0.05,0,-0.0122625,0.0122625\n"), std::string::npos);
  const std::string wind = readAll(path("plots/series_wind.csv"));
  EXPECT_NE(wind.find("\nsemi_implicit_euler,20,16,2,"), std::string::npos);
  EXPECT_NE(wind.find("\nsemi_implicit_euler,1000,16,2,"), std::string::npos);
}

TEST_F(Cli, StudyPlotsSayWhatToInstallWithoutPythonOrMatplotlib) {
  // No interpreter at all.
  ::setenv("TICKFX_PYTHON", path("no/python3").c_str(), 1);
  Result r = run("study --out " + path("study") + " --plots " + path("plots"));
  EXPECT_EQ(r.exit, 1);
  EXPECT_EQ(r.err, "tickfx study: error: cannot run " + path("no/python3") +
                       " (No such file or directory): plotting needs Python 3 with matplotlib "
                       "(Debian: apt-get install python3-matplotlib)\n");
  EXPECT_FALSE(fs::exists(path("plots/wind.png")));
  // Python without its site packages, where Debian keeps matplotlib.
  const std::string bare = path("bare-python3");
  {
    std::ofstream script(bare);
    script << "#!/bin/sh\nexec /usr/bin/python3 -S \"$@\"\n";
  }
  fs::permissions(bare, fs::perms::owner_all);
  ::setenv("TICKFX_PYTHON", bare.c_str(), 1);
  r = run("study --out " + path("study") + " --plots " + path("plots"));
  ::unsetenv("TICKFX_PYTHON");
  EXPECT_EQ(r.exit, 1);
  EXPECT_EQ(r.err, "matplotlib for Python 3 is not installed\ntickfx study: error: " + bare +
                       " has no matplotlib: plotting needs Python 3 with matplotlib (Debian: "
                       "apt-get install python3-matplotlib)\n");
  EXPECT_FALSE(fs::exists(path("plots/constant_acceleration.png")));
}

TEST_F(Cli, PreviewRendersTheFramesAskedForAsPngs) {
  const std::string args =
      "preview samples/fountain.toml --frames 30..40 --every 5 --size 320x180 --out ";
  const Result r = run(args + path("a"));
  ASSERT_EQ(r.exit, 0) << r.err;
  EXPECT_EQ(r.out, "samples/fountain.toml: 3 frames rendered to " + path("a") +
                       " (320x180), frames 30..40 every 5\n");
  for (const char* name : {"frame_0030.png", "frame_0035.png", "frame_0040.png"}) {
    const auto size = pngSize(readAll(path(std::string("a/") + name)));
    EXPECT_EQ(size, (std::pair<std::uint32_t, std::uint32_t>{320, 180})) << name;
  }
  EXPECT_FALSE(fs::exists(path("a/frame_0031.png")));
  EXPECT_FALSE(fs::exists(path("a/frame_0045.png")));
  EXPECT_EQ(std::distance(fs::directory_iterator(path("a")), fs::directory_iterator{}), 3);
  // The same bytes from another run, and a frame rendered alone is the frame of the sequence.
  ASSERT_EQ(run(args + path("b")).exit, 0);
  ASSERT_EQ(
      run("preview samples/fountain.toml --frames 35..35 --size 320x180 --out " + path("c")).exit,
      0);
  const std::string frame = readAll(path("a/frame_0035.png"));
  EXPECT_EQ(readAll(path("b/frame_0035.png")), frame);
  // The camera frames the whole run, whatever frames are drawn: the same picture.
  EXPECT_EQ(readAll(path("c/frame_0035.png")), frame);
  // The frames kept from the framing pass are those a second run gives.
  ASSERT_EQ(run(args + path("k") + " --keep-mb 0").exit, 0);
  EXPECT_EQ(readAll(path("k/frame_0035.png")), frame);
  // The same bytes from a simulation on one thread and on two.
  for (const char* threads : {"1", "2"}) {
    const std::string dir = path(std::string("t") + threads);
    ASSERT_EQ(run(args + dir + " --set simulation.threads=" + threads).exit, 0);
    EXPECT_EQ(readAll(dir + "/frame_0035.png"), frame) << threads << " thread(s)";
  }
  // Particles are drawn: without the guides, below the caption band, the risen fountain's frame
  // has hundreds of pixels that are not the background (an empty picture has none).
  ASSERT_EQ(run("preview samples/fountain.toml --frames 35..35 --size 320x180 --no-guides --out " +
                path("n"))
                .exit,
            0);
  const tickfx::test::DecodedPng shown = tickfx::test::decodePng(readAll(path("n/frame_0035.png")));
  ASSERT_EQ(shown.error, "");
  const tickfx::preview::Rgb bg = tickfx::preview::RenderSettings{}.background;
  const std::array<int, 3> background = {bg[0], bg[1], bg[2]};
  int drawn = 0;
  for (int y = 16; y < shown.height; ++y) {
    for (int x = 0; x < shown.width; ++x) drawn += shown.at(x, y) != background ? 1 : 0;
  }
  EXPECT_GT(drawn, 300);
  // A sheet of the three frames: one row of cells a quarter the size.
  const Result sheet = run(args + path("s") + " --sheet");
  ASSERT_EQ(sheet.exit, 0) << sheet.err;
  EXPECT_EQ(pngSize(readAll(path("s/sheet.png"))),
            (std::pair<std::uint32_t, std::uint32_t>{3 * 80, 45}));
  EXPECT_NE(sheet.out.find("sheet: " + path("s/sheet.png") + " (3 frames, 80x45 cells)\n"),
            std::string::npos)
      << sheet.out;
  EXPECT_EQ(readAll(path("s/frame_0035.png")), frame);  // the frames are as without a sheet
}

TEST_F(Cli, PreviewRefusesBadInputWithNothingWritten) {
  const std::string fountain = "preview samples/fountain.toml --out " + path("never") + " ";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {fountain + "--color bogus",
       "tickfx preview: --color: 'bogus' (expected speed, age, nage, id, life or mass)\n"},
      {fountain + "--lookat 0,0,0",
       "tickfx preview: --lookat needs --camera (without it the "
       "camera frames the run)\n"},
      {fountain + "--camera 1,2,3 --lookat 1,2,3",
       "tickfx preview: --camera: the camera is on the point it looks at\n"},
      {fountain + "--camera 0,5,0 --lookat 0,0,0",
       "tickfx preview: --camera: the camera's up is along its view\n"},
      {fountain + "--camera 1,2",
       "tickfx preview: --camera: '1,2' is not a point X,Y,Z (metres, "
       "three numbers from -1e9 to 1e9)\n"},
      {fountain + "--up x", "tickfx preview: --up: 'x' (expected y or z)\n"},
      {fountain + "--point-size 3 --radius 0.1",
       "tickfx preview: --point-size and --radius each set the splat size: give one\n"},
      {fountain + "--size 0x720",
       "tickfx preview: --size: '0x720' is not WxH with whole numbers from 1 to 16384\n"},
      {fountain + "--size 1000000x720",
       "tickfx preview: --size: '1000000x720' is not WxH with whole numbers from 1 to 16384\n"},
      {fountain + "--frames 0..3",
       "tickfx preview: --frames: '0..3' is not a range A..B of this effect's frames (1..120)\n"},
      {fountain + "--every 0",
       "tickfx preview: --every: '0' is not a whole number in [1, 1000000]\n"},
  };
  for (const auto& [args, message] : cases) {
    const Result r = run(args);
    EXPECT_EQ(r.exit, 2) << args;
    EXPECT_EQ(r.err, message) << args;
    EXPECT_FALSE(fs::exists(path("never"))) << args;
  }
  // No ffmpeg: --mp4 says what to install, before running anything.
  ::setenv("TICKFX_FFMPEG", path("no/ffmpeg").c_str(), 1);
  const Result mp4 = run(fountain + "--mp4");
  ::unsetenv("TICKFX_FFMPEG");
  EXPECT_EQ(mp4.exit, 2);
  EXPECT_EQ(mp4.err,
            "tickfx preview: --mp4 needs ffmpeg, which is not installed (Debian: apt-get install "
            "ffmpeg; --gif needs nothing more)\n");
  // A folder with no frame caches in it.
  fs::create_directories(path("empty"));
  { std::ofstream(path("empty/notes.txt")) << "x"; }
  const Result empty = run("preview " + path("empty") + " --out " + path("never"));
  EXPECT_EQ(empty.exit, 2);
  EXPECT_EQ(empty.err, path("empty") +
                           ": error: no frame caches here (expected frame_0001.vdb, .ply or .csv, "
                           "as tickfx run writes them)\n");
  EXPECT_FALSE(fs::exists(path("never")));
  // An output folder that cannot be made: a file stands where it would go.
  { std::ofstream(path("file")) << "x"; }
  const Result r = run("preview samples/fountain.toml --out " + path("file/sub"));
  EXPECT_EQ(r.exit, 2);
  EXPECT_EQ(r.err, path("file/sub") + ": error: cannot make the output folder (Not a directory)\n");
}

TEST_F(Cli, PreviewRendersACacheFolderAndItsAttributes) {
  ASSERT_EQ(
      run("run samples/fountain.toml --frames 12 --fps 24 --format ply --out " + path("fountain"))
          .exit,
      0);
  const std::string args = "preview " + path("fountain") + " --size 160x90 --out ";
  const Result r = run(args + path("p") + " --frames 10..12 --color mass");
  ASSERT_EQ(r.exit, 0) << r.err;
  EXPECT_EQ(r.out, path("fountain") + ": 3 frames rendered to " + path("p") +
                       " (160x90), frames 10..12 every 1\n");
  EXPECT_EQ(pngSize(readAll(path("p/frame_0012.png"))),
            (std::pair<std::uint32_t, std::uint32_t>{160, 90}));
  EXPECT_FALSE(fs::exists(path("p/frame_0009.png")));
  // The folder's frames are those of the run: the same picture from the effect and its caches.
  ASSERT_EQ(run("preview samples/fountain.toml --size 160x90 --color mass --out " + path("e") +
                " --set output.seconds=0.5")
                .exit,
            0);
  EXPECT_EQ(readAll(path("e/frame_0012.png")), readAll(path("p/frame_0012.png")));
  // An attribute the caches do not have is refused, naming those they do.
  const Result bad = run(args + path("never") + " --color Cd");
  EXPECT_EQ(bad.exit, 2);
  EXPECT_EQ(bad.err,
            "tickfx preview: --color: 'Cd' (expected speed, age, nage, id, life or mass)\n");
  EXPECT_FALSE(fs::exists(path("never")));
  // A looping GIF of the frames rendered: GIF89a, the frame size, the NETSCAPE loop.
  const Result gif = run(args + path("g") + " --gif --every 4");
  ASSERT_EQ(gif.exit, 0) << gif.err;
  EXPECT_NE(gif.out.find("flipbook: " + path("g/flipbook.gif") + " (3 frames, 4/100 s each)\n"),
            std::string::npos)
      << gif.out;
  const std::string bytes = readAll(path("g/flipbook.gif"));
  ASSERT_GT(bytes.size(), 13u);
  EXPECT_EQ(bytes.substr(0, 6), "GIF89a");
  EXPECT_EQ(static_cast<unsigned char>(bytes[6]) | static_cast<unsigned char>(bytes[7]) << 8, 160);
  EXPECT_EQ(static_cast<unsigned char>(bytes[8]) | static_cast<unsigned char>(bytes[9]) << 8, 90);
  EXPECT_NE(bytes.find("NETSCAPE2.0"), std::string::npos);
}

TEST_F(Cli, PreviewColoursCachesByTheirOwnCdUnlessToldOtherwise) {
  // Two frames of a row of particles, red to blue along the row, as another tool might cache them.
  fs::create_directories(path("cd"));
  for (int f = 1; f <= 2; ++f) {
    tickfx::io::FrameData frame;
    frame.resize(5, {"Cd_r", "Cd_g", "Cd_b"});
    for (Eigen::Index i = 0; i < 5; ++i) {
      frame.id[static_cast<std::size_t>(i)] = static_cast<std::uint64_t>(i);
      frame.position.x[i] = static_cast<float>(i);
      frame.position.y[i] = 0.5f * static_cast<float>(f);
      frame.position.z[i] = 0.0f;
      frame.velocity.x[i] = frame.velocity.y[i] = frame.velocity.z[i] = static_cast<float>(i);
      frame.age[i] = 0.0f;
      frame.life[i] = 1.0f;
      frame.mass[i] = 1.0f;
      frame.attributes[0][i] = 1.0f - 0.25f * static_cast<float>(i);
      frame.attributes[1][i] = 0.0f;
      frame.attributes[2][i] = 0.25f * static_cast<float>(i);
    }
    tickfx::io::writeCsvCache(frame, path("cd/frame_000" + std::to_string(f) + ".csv"));
  }
  const std::string args = "preview " + path("cd") + " --size 160x90 --point-size 9 --out ";
  for (const char* name : {"default", "Cd", "speed"}) {
    const std::string colour =
        std::string(name) == "default" ? "" : std::string(" --color ") + name;
    const Result r = run(args + path(std::string("p_") + name) + colour);
    ASSERT_EQ(r.exit, 0) << name << ": " << r.err;
  }
  const std::string byDefault = readAll(path("p_default/frame_0002.png"));
  EXPECT_EQ(byDefault, readAll(path("p_Cd/frame_0002.png")));
  EXPECT_NE(byDefault, readAll(path("p_speed/frame_0002.png")));
}

TEST_F(Cli, PreviewPipesItsFramesToFfmpegForAMovie) {
  // A stand-in for ffmpeg: keeps what it is sent as the movie, and its arguments.
  const std::string fake = path("ffmpeg");
  {
    std::ofstream script(fake);
    script << "#!/bin/sh\nfor last; do :; done\necho \"$@\" > \"$last.args\"\ncat > \"$last\"\n";
  }
  fs::permissions(fake, fs::perms::owner_all);
  ::setenv("TICKFX_FFMPEG", fake.c_str(), 1);
  const std::string args =
      "preview samples/fountain.toml --size 160x90 --frames 20..22 --mp4 --out " + path("m");
  const Result r = run(args);
  ASSERT_EQ(r.exit, 0) << r.err;
  EXPECT_NE(r.out.find("movie: " + path("m/flipbook.mp4") + "\n"), std::string::npos) << r.out;
  // Three frames of 160 × 90 RGB, at the effect's 24 fps, into a temporary renamed into place.
  EXPECT_EQ(fs::file_size(path("m/flipbook.mp4")), 3u * 160 * 90 * 3);
  const std::string given = readAll(path("m/flipbook.mp4.partial.mp4.args"));
  EXPECT_NE(given.find("-f rawvideo -pix_fmt rgb24 -s 160x90 -r 24 -i -"), std::string::npos)
      << given;
  EXPECT_FALSE(fs::exists(path("m/flipbook.mp4.partial.mp4")));
  // An ffmpeg that fails leaves no movie and says so.
  {
    std::ofstream script(fake);
    script << "#!/bin/sh\ncat > /dev/null\nexit 3\n";
  }
  const Result failed = run(args + "2");
  ::unsetenv("TICKFX_FFMPEG");
  EXPECT_EQ(failed.exit, 1);
  EXPECT_EQ(failed.err,
            path("m2/flipbook.mp4") + ": error: ffmpeg failed (exit status 3); no movie written\n");
  EXPECT_FALSE(fs::exists(path("m2/flipbook.mp4")));
  EXPECT_FALSE(fs::exists(path("m2/flipbook.mp4.partial.mp4")));
}

// Bad effect files through the command line: exit code 2, the first message exactly (file, line,
// column, key path, what is wrong and what is expected), and no output folder created. The io
// tests check every message of these and more cases through the library.
struct BadEffect {
  const char* name;
  const char* text;
  const char* firstMessage;  // after the file name
};

const BadEffect kBadEffects[] = {
    {"empty", "", ":1:1: error: format_version: missing (expected format_version = 1)"},
    {"wrong_type",
     "format_version = 1\n[simulation]\nstep_rate = 60\nintegrator = 42\n[[emitters]]\nrate = "
     "10.0\n",
     ":4:14: error: simulation.integrator: got the integer 42 (expected integrator, one of: "
     "explicit_euler, semi_implicit_euler, midpoint, position_verlet, velocity_verlet, rk4)"},
    {"missing_step_rate",
     "format_version = 1\n[simulation]\nintegrator = \"rk4\"\n[[emitters]]\nrate = 1.0\n",
     ":2:1: error: simulation.step_rate: missing (expected ticks per second (Hz), an integer from "
     "1 to 1000000)"},
    {"unknown_key",
     "format_version = 1\n[simulation]\nstep_rate = 60\n[[emitters]]\nrate = 10.0\nsped = 3.0\n",
     ":6:1: error: emitters.0.sped: unknown key \"sped\" (did you mean \"speed\"?)"},
    {"negative_rate",
     "format_version = 1\n[simulation]\nstep_rate = 60\n[[emitters]]\nrate = -5.0\n",
     ":5:8: error: emitters.0.rate: -5 is out of range (expected particles per second, a number "
     "from 0 to 1e9)"},
    {"zero_step_rate",
     "format_version = 1\n[simulation]\nstep_rate = 0\n[[emitters]]\nrate = 1.0\n",
     ":3:13: error: simulation.step_rate: 0 is out of range (expected ticks per second (Hz), an "
     "integer from 1 to 1000000)"},
    {"nan", "format_version = 1\n[simulation]\nstep_rate = 60\n[[emitters]]\nrate = nan\n",
     ":5:8: error: emitters.0.rate: nan is not a finite number (expected particles per second, a "
     "number from 0 to 1e9)"},
    {"inf", "format_version = 1\n[simulation]\nstep_rate = 60\n[[emitters]]\nspeed = inf\n",
     ":5:9: error: emitters.0.speed: inf is not a finite number (expected metres per second, a "
     "number from 0 to 1e9)"},
    {"absurd_count",
     "format_version = 1\n[simulation]\nstep_rate = 60\nmax_particles = "
     "100000000000\n[[emitters]]\nrate = 10.0\n",
     ":4:17: error: simulation.max_particles: 100000000000 is out of range (expected an integer "
     "from 1 to 1000000000)"},
    {"malformed", "format_version = 1\n[simulation\nstep_rate = 60\n",
     ":2:12: error: Error while parsing table header: expected ']', saw '\\n'"},
    {"misspelt_integrator",
     "format_version = 1\n[simulation]\nstep_rate = 60\nintegrator = "
     "\"semi_implict_euler\"\n[[emitters]]\nrate = 10.0\n",
     ":4:14: error: simulation.integrator: unknown integrator \"semi_implict_euler\" (did you mean "
     "\"semi_implicit_euler\"?)"},
    {"unknown_force",
     "format_version = 1\n[simulation]\nstep_rate = 60\n[[emitters]]\nrate = "
     "10.0\n[[forces]]\ntype = \"gravty\"\n",
     ":7:8: error: forces.0.type: unknown force type \"gravty\" (did you mean \"gravity\"?)"},
    {"unknown_shape",
     "format_version = 1\n[simulation]\nstep_rate = 60\n[[emitters]]\nrate = 10.0\nshape = "
     "\"cube\"\n",
     ":6:9: error: emitters.0.shape: unknown shape \"cube\" (expected one of: point, sphere, box, "
     "disc)"},
    {"absurd_burst",
     "format_version = 1\n[simulation]\nstep_rate = 60\n[[emitters]]\nbursts = [{ time = 0.0, "
     "count = 20000000000 }]\n",
     ":5:33: error: emitters.0.bursts.0.count: 20000000000 is out of range (expected particles, an "
     "integer from 1 to simulation.max_particles = 1000000)"},
    {"bad_fps",
     "format_version = 1\n[simulation]\nstep_rate = 60\n[[emitters]]\nrate = 10.0\n[output]\nfps = "
     "\"30000/0\"\n",
     ":7:7: error: output.fps: \"30000/0\" is out of range (expected frames per second, an integer "
     "from 1 to 1000000 or a ratio string like \"30000/1001\")"},
    {"future_version",
     "format_version = 7\n[simulation]\nstep_rate = 60\n[[emitters]]\nrate = 1.0\n",
     ":1:18: error: format_version: version 7 is not one this build reads (expected 1)"},
    {"wind_without_frequency",
     "format_version = 1\n[simulation]\nstep_rate = 60\n[[emitters]]\nrate = "
     "10.0\n[[forces]]\ntype = \"wind\"\namplitude = 1.0\n",
     ":6:1: error: forces.0.frequency: missing (expected hertz, a number from 0 to 1000000)"},
    // What only the core types refused (run exited 1 with no position, check passed): each
    // type's validate() is asked at load.
    {"tiny_direction",
     "format_version = 1\n[simulation]\nstep_rate = 60\n[[emitters]]\ndirection = [1e-200, "
     "1e-200, 0]\nbursts = [{ time = 0.0, count = 1 }]\n",
     ":5:13: error: emitters.0.direction: is too short to normalise in double precision (expected "
     "a direction [x, y, z] at least 1.5e-154 long)"},
    {"tiny_disc_normal",
     "format_version = 1\n[simulation]\nstep_rate = 60\n[[emitters]]\nshape = \"disc\"\nnormal "
     "= [1e-200, 0, 0]\nbursts = [{ time = 0.0, count = 1 }]\n",
     ":6:10: error: emitters.0.normal: is too short to normalise in double precision (expected a "
     "direction [x, y, z] at least 1.5e-154 long)"},
    {"tiny_wind_direction",
     "format_version = 1\n[simulation]\nstep_rate = 60\n[[emitters]]\nbursts = [{ time = 0.0, "
     "count = 1 }]\n[[forces]]\ntype = \"wind\"\ndirection = [1e-50, 0, 0]\namplitude = "
     "1.0\nfrequency = 1.0\n",
     ":8:13: error: forces.0.direction: is too short to normalise in float precision (expected a "
     "direction [x, y, z] at least 1.1e-19 long)"},
    {"tiny_rope",
     "format_version = 1\n[simulation]\nstep_rate = 60\n[[emitters]]\ntype = \"rope\"\nend = "
     "[1e-200, 0, 0]\ncount = 3\nstiffness = 1\n",
     ":6:7: error: emitters.0.end: is 1e-200 m from start, too close to give the rope a length in "
     "double precision (expected [x, y, z] in metres, at least 1.5e-154 m from start)"},
    {"tiny_cloth_axis",
     "format_version = 1\n[simulation]\nstep_rate = 60\n[[emitters]]\ntype = \"cloth\"\naxis_u "
     "= [1e-200, 0, 0]\nwidth = 2\nheight = 2\nspacing = 1\nstiffness = 1\n",
     ":6:10: error: emitters.0.axis_u: is too short to normalise in double precision (expected a "
     "direction [x, y, z] at least 1.5e-154 long)"},
    {"tiny_vortex_axis",
     "format_version = 1\n[simulation]\nstep_rate = 60\n[[emitters]]\nbursts = [{ time = 0.0, "
     "count = 1 }]\n[[forces]]\ntype = \"vector_field\"\nmode = \"drag\"\nbake = { kind = "
     "\"vortex\", axis = [0, 1e-200, 0] }\n",
     ":9:34: error: forces.0.bake.axis: is too short to normalise in double precision (expected a "
     "direction [x, y, z] at least 1.5e-154 long)"},
    {"tiny_shear_gradient",
     "format_version = 1\n[simulation]\nstep_rate = 60\n[[emitters]]\nbursts = [{ time = 0.0, "
     "count = 1 }]\n[[forces]]\ntype = \"vector_field\"\nbake = { kind = \"shear\", gradient = "
     "[0, 1e-170, 0] }\n",
     ":8:37: error: forces.0.bake.gradient: is too short to normalise in double precision "
     "(expected a direction [x, y, z] at least 1.5e-154 long)"},
};

class CliBadEffect : public Cli, public ::testing::WithParamInterface<BadEffect> {};

TEST_P(CliBadEffect, ExitsTwoWithTheMessageAndWritesNothing) {
  const BadEffect& bad = GetParam();
  const std::string file = writeFile(std::string(bad.name) + ".toml", bad.text);
  for (const std::string command : {"run", "check"}) {
    const Result r =
        run(command + " " + file + (command == "run" ? " --out " + path("never") : ""));
    EXPECT_EQ(r.exit, 2) << command;
    EXPECT_EQ(r.err.substr(0, r.err.find('\n')), file + bad.firstMessage) << command;
    EXPECT_EQ(r.out, "") << command;
    EXPECT_FALSE(fs::exists(path("never"))) << command;
  }
}

INSTANTIATE_TEST_SUITE_P(Files, CliBadEffect, ::testing::ValuesIn(kBadEffects),
                         [](const ::testing::TestParamInfo<BadEffect>& p) {
                           return std::string(p.param.name);
                         });

}  // namespace
