// The command line when the machine fails it: writes that cannot be made (a file size limit, a
// full disk, a directory removed or made read-only during the run) and SIGINT or SIGTERM. Each
// run must stop with its exit code and a message naming the file and the system's reason, and
// leave only whole frames behind: the frames it wrote are the bytes an undisturbed run writes.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

#include "CliTestSupport.h"
#include "io/cache/PlyCache.h"

namespace fs = std::filesystem;

namespace {

using tickfx::cli_test::readAll;
using tickfx::cli_test::Result;

class CliFaults : public tickfx::cli_test::CliFixture {
 protected:
  CliFaults() : CliFixture("tickfx_faults") {}

  // The fountain sample from its first frame, caches of `format` into `out`.
  static std::vector<std::string> fountain(const std::string& format, const std::string& out,
                                           const std::string& seconds = "5") {
    return {
        "run",    "samples/fountain.toml", "--format", format, "--out", out, "--seconds", seconds,
        "--quiet"};
  }
  static std::string quoted(const std::vector<std::string>& args) {
    std::string text;
    for (const std::string& a : args) text += " '" + a + "'";
    return text;
  }

  // Waits until `file` exists (the run has got that far); fails the test after a minute.
  static void waitFor(const fs::path& file) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::minutes(1);
    while (!fs::exists(file)) {
      ASSERT_LT(std::chrono::steady_clock::now(), deadline) << "the run never wrote " << file;
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  }

  // Runs `tickfx ARGS`, sends `signal` once `file` exists, and waits for the run to end.
  Result interruptedAt(const std::vector<std::string>& args, const fs::path& file,
                       int signal) const {
    const auto running = startProgram(TICKFX_CLI, args);
    waitFor(file);
    EXPECT_EQ(::kill(running.pid, signal), 0);
    return finish(running);
  }

  // What the signal handler writes when the first signal arrives, as a regex.
  static inline const std::string kStoppingNote =
      "\ntickfx: stopping after the frame in hand \\(a second Ctrl-C stops at once\\)\n";

  // `dir` holds frame_0001.EXT to frame_LAST.EXT (and `extra` files), nothing else: no temporary.
  static void expectOnlyFrames(const fs::path& dir, const std::string& ext, int last,
                               std::vector<std::string> extra = {}) {
    std::vector<std::string> expected = std::move(extra), found;
    for (int f = 1; f <= last; ++f) {
      char name[32];
      std::snprintf(name, sizeof name, "frame_%04d.%s", f, ext.c_str());
      expected.push_back(name);
    }
    for (const auto& entry : fs::directory_iterator(dir)) found.push_back(entry.path().filename());
    std::sort(expected.begin(), expected.end());
    std::sort(found.begin(), found.end());
    EXPECT_EQ(found, expected);
  }

  // Frames 1 to `last` of `dir` are byte for byte those of an undisturbed run of the same effect.
  void expectTheUndisturbedBytes(const fs::path& dir, const std::string& ext, int last) const {
    const std::string reference = path("reference_" + ext);
    auto args = fountain(ext, reference);
    args.insert(args.end(), {"--frames", std::to_string(last)});
    args.erase(args.begin() + 6, args.begin() + 8);  // --frames in place of --seconds
    ASSERT_EQ(runProgram(TICKFX_CLI, quoted(args).substr(1)).exit, 0);
    for (int f = 1; f <= last; ++f) {
      char name[32];
      std::snprintf(name, sizeof name, "frame_%04d.%s", f, ext.c_str());
      EXPECT_EQ(readAll(dir / name), readAll(fs::path(reference) / name)) << name;
    }
  }
};

// A write that fails: "OUT/frame_N.EXT: error: cannot write (REASON)", then the frames before
// it. Returns N - 1, the last whole frame (-1 when the message is not that).
int lastWholeFrame(const Result& r, const std::string& out, const std::string& ext,
                   const std::string& reason) {
  const std::regex message("(.*)/frame_([0-9]{4})\\." + ext + ": error: cannot write \\(" + reason +
                           "\\)\ncaches written: (.*) \\(frame_0001 to frame_([0-9]{4})\\)\n");
  std::smatch m;
  if (!std::regex_match(r.err, m, message) || m[1] != out || m[3] != out) return -1;
  const int failed = std::stoi(m[2]), last = std::stoi(m[4]);
  return last == failed - 1 ? last : -1;
}

// ulimit -f on a farm node: the kernel refuses to grow a file past the limit (EFBIG). Every
// format stops at the first frame that outgrows 60 000 bytes, on the frame the bytes say.
TEST_F(CliFaults, AFileSizeLimitStopsTheRunAtTheFirstFrameItCannotWrite) {
  const std::pair<const char*, int> formats[] = {{"csv", 8}, {"ply", 16}, {"vdb", 8}};
  for (const auto& [ext, last] : formats) {
    const std::string out = path(std::string("limited_") + ext);
    const Result r =
        runProgram("prlimit", "--fsize=60000 -- '" TICKFX_CLI "'" + quoted(fountain(ext, out)));
    EXPECT_EQ(r.exit, 1) << r.err;
    char failedName[32], lastName[16];
    std::snprintf(failedName, sizeof failedName, "frame_%04d.%s", last + 1, ext);
    std::snprintf(lastName, sizeof lastName, "frame_%04d", last);
    EXPECT_EQ(r.err, out + "/" + failedName + ": error: cannot write (File too large)\n" +
                         "caches written: " + out + " (frame_0001 to " + lastName + ")\n")
        << ext;
    EXPECT_EQ(lastWholeFrame(r, out, ext, "File too large"), last);
    expectOnlyFrames(out, ext, last);
    expectTheUndisturbedBytes(out, ext, last);
  }
}

// A disk that fills up: a 192 KiB tmpfs mounted in a mount namespace of the run's own (where the
// machine allows one; under CI=true it must). The frames are copied out before the namespace, and
// its tmpfs, go away.
TEST_F(CliFaults, AFullDiskStopsTheRunAtTheFirstFrameItCannotWrite) {
  const std::string out = path("full"), copy = path("copy");
  fs::create_directories(out);
  fs::create_directories(copy);
  const std::string script =
      "mount -t tmpfs -o size=192k tickfx-full \"$1\" || exit 99; shift; out=$1; copy=$2; shift 2;"
      " \"$@\"; rc=$?; cp -a \"$out\"/. \"$copy\"/; exit $rc";
  const Result probe = runProgram(
      "unshare", "-m sh -c 'mount -t tmpfs -o size=64k t " + out + " && touch " + out + "/x'");
  if (probe.exit != 0) {
    // CI runs as root on a machine that has them: there a skip would hide a lost test.
    const char* ci = std::getenv("CI");
    if (ci != nullptr && std::string(ci) == "true") {
      FAIL() << "CI=true, and no mount namespace with a tmpfs (unshare -m: " << probe.err << ")";
    }
    GTEST_SKIP() << "no mount namespace with a tmpfs on this machine (unshare -m: " << probe.err
                 << "); the file size limit test covers the same path";
  }
  ASSERT_TRUE(fs::is_empty(out)) << "the probe's tmpfs leaked into the test's namespace";
  const Result r =
      runProgram("unshare", "-m sh -c '" + script + "' sh '" + out + "' '" + out + "' '" + copy +
                                "' '" TICKFX_CLI "'" + quoted(fountain("csv", out)));
  EXPECT_EQ(r.exit, 1) << r.err;
  const int last = lastWholeFrame(r, out, "csv", "No space left on device");
  ASSERT_GE(last, 1) << r.err;
  expectOnlyFrames(copy, "csv", last);
  expectTheUndisturbedBytes(copy, "csv", last);
}

TEST_F(CliFaults, AnOutputDirectoryRemovedDuringTheRunStopsIt) {
  const std::string out = path("removed");
  const auto running = startProgram(TICKFX_CLI, fountain("csv", out, "120"));
  waitFor(fs::path(out) / "frame_0003.csv");
  // The run keeps writing while the folder goes: removal is retried until it is gone.
  std::error_code ec;
  while (fs::exists(out)) fs::remove_all(out, ec);
  const Result r = finish(running);
  EXPECT_EQ(r.exit, 1) << r.err;
  EXPECT_GE(lastWholeFrame(r, out, "csv", "No such file or directory"), 3) << r.err;
  EXPECT_FALSE(fs::exists(out)) << "nothing is written once the folder is gone";
}

// Permission denied. Root writes anywhere, so as root the run is started as nobody (setpriv).
TEST_F(CliFaults, AnOutputDirectoryMadeReadOnlyDuringTheRunStopsIt) {
  const std::string out = path("readonly");
  fs::create_directories(out);
  fs::permissions(out, fs::perms::all);
  std::vector<std::string> args = fountain("csv", out, "120");
  std::string program = TICKFX_CLI;
  if (::geteuid() == 0) {
    fs::permissions(dir_, fs::perms::all);  // stdout.txt and stderr.txt are opened before setpriv
    args.insert(args.begin(), {"--reuid=65534", "--regid=65534", "--clear-groups", TICKFX_CLI});
    program = "/usr/bin/setpriv";
  }
  const auto running = startProgram(program, args);
  waitFor(fs::path(out) / "frame_0003.csv");
  fs::permissions(out, fs::perms::owner_read | fs::perms::owner_exec | fs::perms::group_read |
                           fs::perms::group_exec | fs::perms::others_read | fs::perms::others_exec);
  const Result r = finish(running);
  fs::permissions(out, fs::perms::all);
  EXPECT_EQ(r.exit, 1) << r.err;
  // The folder may turn read-only between two frames (the next temporary cannot be made) or
  // while a temporary is open (it cannot be renamed, nor removed): then a second line names it.
  std::smatch leftover;
  std::string err = r.err;
  std::vector<std::string> extra;
  if (std::regex_search(err, leftover,
                        std::regex("\n" + out +
                                   "/(frame_[0-9]{4}\\.csv\\.tmp[0-9]+-[0-9]+): "
                                   "error: cannot remove \\(Permission denied\\)"))) {
    extra.push_back(leftover[1]);
    err.erase(leftover.position(0), leftover.length(0));
  }
  const int last = lastWholeFrame(Result{r.exit, r.out, err}, out, "csv", "Permission denied");
  ASSERT_GE(last, 3) << r.err;
  if (!extra.empty()) {
    char temp[32];
    std::snprintf(temp, sizeof temp, "frame_%04d.csv.tmp", last + 1);
    EXPECT_EQ(extra[0].rfind(temp, 0), 0u) << extra[0];
  }
  expectOnlyFrames(out, "csv", last, extra);
  expectTheUndisturbedBytes(out, "csv", last);
}

// Ctrl-C: the frame in hand is finished, a checkpoint of it written, and the run resumed from it
// reaches the state hash of the run that was never stopped.
TEST_F(CliFaults, SigintFinishesTheFrameCheckpointsItAndTheResumedRunReachesTheSameHash) {
  const std::string out = path("interrupted");
  std::vector<std::string> args = fountain("ply", out, "10");
  args.insert(args.end(), {"--checkpoint-every", "5"});
  const Result r = interruptedAt(args, fs::path(out) / "checkpoint_000005.tfxc", SIGINT);
  EXPECT_EQ(r.exit, 130) << r.err;
  const std::regex message(
      kStoppingNote +
      "samples/fountain.toml: interrupted by SIGINT after frame ([0-9]+) \\(([0-9.]+) s\\)\n"
      "caches written: (.*) \\(frame_0001 to frame_([0-9]{4})\\)\n"
      "checkpoint: (.*)/checkpoint_([0-9]{6})\\.tfxc\n"
      "resume with: tickfx run samples/fountain.toml --resume (.*) \\(and the options of this "
      "run\\)\n");
  std::smatch m;
  ASSERT_TRUE(std::regex_match(r.err, m, message)) << r.err;
  const int last = std::stoi(m[1]);
  EXPECT_GE(last, 5);
  char seconds[32];
  std::snprintf(seconds, sizeof seconds, "%.9g", last / 24.0);
  EXPECT_EQ(m[2], seconds);
  EXPECT_EQ(m[3], out);
  EXPECT_EQ(std::stoi(m[4]), last);
  EXPECT_EQ(m[5], out);
  EXPECT_EQ(std::stoi(m[6]), last);
  const std::string checkpoint = m[7];
  EXPECT_EQ(checkpoint, out + "/" + fs::path(checkpoint).filename().string());
  // The frames it wrote and its checkpoints (every 5th frame and the last), nothing else.
  std::vector<std::string> checkpoints;
  auto checkpointName = [](int frame) {
    char name[32];
    std::snprintf(name, sizeof name, "checkpoint_%06d.tfxc", frame);
    return std::string(name);
  };
  for (int f = 5; f <= last; f += 5) checkpoints.push_back(checkpointName(f));
  if (last % 5 != 0) checkpoints.push_back(fs::path(checkpoint).filename());
  expectOnlyFrames(out, "ply", last, checkpoints);
  expectTheUndisturbedBytes(out, "ply", last);

  auto hashOf = [&](std::vector<std::string> extra) {
    std::vector<std::string> a = {
        "run", "samples/fountain.toml", "--format", "none", "--seconds", "10", "--hash", "--quiet"};
    a.insert(a.end(), extra.begin(), extra.end());
    const Result done = runProgram(TICKFX_CLI, quoted(a).substr(1));
    EXPECT_EQ(done.exit, 0) << done.err;
    return done.out;
  };
  const std::string resumed = hashOf({"--resume", checkpoint});
  EXPECT_NE(resumed.find("state-hash: "), std::string::npos) << resumed;
  EXPECT_EQ(resumed, hashOf({}));
}

// kill: the same, and a run without checkpoints says it cannot be resumed.
TEST_F(CliFaults, SigtermWithoutCheckpointsStopsAfterTheFrameAndSaysItCannotResume) {
  const std::string out = path("terminated");
  const Result r =
      interruptedAt(fountain("csv", out, "60"), fs::path(out) / "frame_0003.csv", SIGTERM);
  EXPECT_EQ(r.exit, 143) << r.err;
  const std::regex message(
      kStoppingNote +
      "samples/fountain.toml: interrupted by SIGTERM after frame ([0-9]+) \\([0-9.]+ s\\)\n"
      "caches written: .* \\(frame_0001 to frame_([0-9]{4})\\)\n"
      "no checkpoint: run with --checkpoint-every N to be able to resume\n");
  std::smatch m;
  ASSERT_TRUE(std::regex_match(r.err, m, message)) << r.err;
  EXPECT_EQ(std::stoi(m[1]), std::stoi(m[2]));
  expectOnlyFrames(out, "csv", std::stoi(m[1]));
  expectTheUndisturbedBytes(out, "csv", std::stoi(m[1]));
}

// The study's tables under a file-size limit between its files' sizes (constant_acceleration.csv
// about 3.9 kB, oscillator.csv 1.1 kB, wind.csv 4.1 kB): the third is refused by name and with
// the system's reason, and the two before it are whole, the bytes of an unlimited run.
TEST_F(CliFaults, AFileSizeLimitStopsTheStudyAtTheTableItCannotWrite) {
  const std::string whole = path("whole"), limited = path("limited");
  ASSERT_EQ(runProgram(TICKFX_CLI, "study --out " + whole).exit, 0);
  ASSERT_LT(std::filesystem::file_size(whole + "/constant_acceleration.csv"), 4000u);
  ASSERT_GT(std::filesystem::file_size(whole + "/wind.csv"), 4000u);
  const Result r = runProgram("prlimit", "--fsize=4000 -- '" TICKFX_CLI "' study --out " + limited);
  EXPECT_EQ(r.exit, 1);
  EXPECT_EQ(r.err, limited + "/wind.csv: error: cannot write (File too large)\n");
  for (const char* name : {"constant_acceleration.csv", "oscillator.csv"}) {
    EXPECT_EQ(readAll(limited + "/" + name), readAll(whole + "/" + name)) << name;
  }
  std::vector<std::string> left;
  for (const auto& entry : std::filesystem::directory_iterator(limited)) {
    left.push_back(entry.path().filename().string());
  }
  std::sort(left.begin(), left.end());
  EXPECT_EQ(left, (std::vector<std::string>{"constant_acceleration.csv", "oscillator.csv"}));
}

// An output folder that cannot be made (a file stands where a parent folder should be).
TEST_F(CliFaults, TheStudyNamesAnOutputFolderItCannotMake) {
  { std::ofstream(path("file")) << "x"; }
  const Result r = runProgram(TICKFX_CLI, "study --out " + path("file/study"));
  EXPECT_EQ(r.exit, 1);
  EXPECT_EQ(r.err, path("file/study") + ": error: cannot write (Not a directory)\n");
}

}  // namespace
