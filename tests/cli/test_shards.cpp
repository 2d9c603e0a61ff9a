// Sharded runs: `tickfx run --shard I/N` and `tickfx merge`. Every sample that can be sharded,
// split into 1, 2, 3 and 7 shards and merged, gives the unsharded run's state hash and its files
// byte for byte (caches in every format, the USD layer, checkpoints); a shard resumed from its
// checkpoint too. What cannot be sharded exactly, and shards that do not belong together, are
// refused by name.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "tests/support/CliTestSupport.h"
#include "tests/support/Sanitized.h"

namespace fs = std::filesystem;

namespace {

using tickfx::cli_test::readAll;
using tickfx::cli_test::Result;

class Shards : public tickfx::cli_test::CliFixture {
 protected:
  Shards() : CliFixture("tickfx_shards") {}

  Result run(const std::string& args) const { return runProgram(TICKFX_CLI, args); }
  static std::string hashOf(const Result& r) {
    const std::size_t at = r.out.find("state-hash: ");
    if (at == std::string::npos) return "no hash in: " + r.out + r.err;
    return r.out.substr(at, r.out.find('\n', r.out.find("ticks: ", at)) - at);
  }

  // The unsharded run of `effect` into DIR/whole; its hash lines.
  std::string runWhole(const std::string& effect, const std::string& options) const {
    const Result r = run(effect + " " + options + " --out " + path("whole") + " --hash --quiet");
    EXPECT_EQ(r.exit, 0) << r.err;
    return hashOf(r);
  }
  // Shard i of n into DIR/<n>/s<i>.
  std::string shardDir(int n, int i) const {
    return path(std::to_string(n) + "/s" + std::to_string(i));
  }
  void runShard(const std::string& effect, const std::string& options, int n, int i) const {
    const Result r = run(effect + " " + options + " --shard " + std::to_string(i) + "/" +
                         std::to_string(n) + " --out " + shardDir(n, i) + " --quiet");
    ASSERT_EQ(r.exit, 0) << r.err;
  }
  // Merges the n shards (given last to first: the order does not matter) into DIR/<n>/merged.
  Result merge(int n) const {
    std::string dirs;
    for (int i = n - 1; i >= 0; --i) dirs += shardDir(n, i) + " ";
    return run("merge " + dirs + "--out " + path(std::to_string(n) + "/merged") + " --hash");
  }
  // Every file of DIR/whole is in `merged`, byte for byte; returns how many.
  int expectSameFiles(const std::string& merged) const {
    int files = 0;
    for (const auto& entry : fs::directory_iterator(path("whole"))) {
      const fs::path other = fs::path(merged) / entry.path().filename();
      EXPECT_TRUE(fs::exists(other)) << other;
      EXPECT_TRUE(readAll(entry.path()) == readAll(other)) << other << " differs";
      ++files;
    }
    return files;
  }

  // The whole run of `effect` against its 1, 2, 3 and 7 shards merged. A sanitizer build splits
  // into 1 and 3 only: the same code paths (one shard, several, one with more rows than another)
  // at 7 of every 18 runs of an instrumented CLI, each of which costs seconds there.
  void expectShardsMergeToTheWholeRun(const std::string& effect, const std::string& options) {
    const std::string whole = runWhole(effect, options);
    ASSERT_EQ(whole.rfind("state-hash: ", 0), 0u) << whole;
    const std::vector<int> counts =
        tickfx::test::kSanitized ? std::vector<int>{1, 3} : std::vector<int>{1, 2, 3, 7};
    for (const int n : counts) {
      SCOPED_TRACE(n);
      for (int i = 0; i < n; ++i) runShard(effect, options, n, i);
      const Result r = merge(n);
      ASSERT_EQ(r.exit, 0) << r.err;
      EXPECT_EQ(hashOf(r), whole);
      EXPECT_GT(expectSameFiles(path(std::to_string(n) + "/merged")), 10);
    }
  }
};

// Twelve frames in every format, a checkpoint every six.
const std::string kOptions = "--frames 12 --format csv,ply,vdb,usda --checkpoint-every 6";

class ShardedSample : public Shards, public ::testing::WithParamInterface<const char*> {};

TEST_P(ShardedSample, MergesToTheWholeRunBitForBit) {
  expectShardsMergeToTheWholeRun(std::string("run samples/") + GetParam() + ".toml", kOptions);
}

// Every sample but those with sub-emitters (fireworks, rain, sparks_grind: refused below).
INSTANTIATE_TEST_SUITE_P(Samples, ShardedSample,
                         ::testing::Values("burst", "drum", "flag", "fountain", "jelly", "leaves",
                                           "oscillator", "rope_swing", "sand_on_sphere",
                                           "smoke_drift", "vortex_smoke", "wind_aliasing",
                                           "wind_aliasing_fixed"));

// Three ropes born at different ticks (one dying, its springs with it: structure k goes to shard
// k mod N, so shards hold different structures and their springs merge in the whole run's order)
// beside an emitter of finite lifetimes and a burst.
TEST_F(Shards, StructuresAndLifetimesMerge) {
  std::string effect =
      "format_version = 1\n"
      "[simulation]\nstep_rate = 480\nseed = 11\nmax_particles = 5000\n"
      "[[emitters]]\nname = \"spray\"\nrate = 3000.0\nspeed = 2.0\nspread = 30.0\n"
      "lifetime = 0.05\nlifetime_jitter = 0.5\nbursts = [{ time = 0.04, count = 333 }]\n"
      "[[forces]]\ntype = \"gravity\"\n";
  for (int k = 0; k < 3; ++k) {
    effect +=
        "[[emitters]]\ntype = \"rope\"\nname = \"rope" + std::to_string(k) + "\"\nstart = [0.0, " +
        std::to_string(k) + ".0, 0.0]\nend = [1.0, " + std::to_string(k) +
        ".0, 0.0]\ncount = " + std::to_string(7 + k) +
        "\npin_start = true\nstiffness = 2000.0\nmass = 0.05\ntime = " + std::to_string(0.03 * k) +
        "\n" + (k == 1 ? "lifetime = 0.1\n" : "");
  }
  const std::string file = writeFile("ropes.toml", effect);
  expectShardsMergeToTheWholeRun("run " + file, kOptions);
}

// A shard stopped after frame 6 and resumed from its checkpoint merges as if it had run through.
TEST_F(Shards, AShardResumedFromItsCheckpointMerges) {
  const std::string effect = "run samples/fountain.toml";
  const std::string options = "--frames 12 --format vdb --checkpoint-every 6";
  const std::string whole = runWhole(effect, options);
  for (int i = 0; i < 3; ++i) runShard(effect, options, 3, i);
  // Shard 1 as a run killed after frame 6 leaves it: frames 7 on, the final state and the
  // manifest gone.
  const fs::path s1 = shardDir(3, 1);
  for (const char* name :
       {"frame_0007.vdb", "frame_0008.vdb", "frame_0009.vdb", "frame_0010.vdb", "frame_0011.vdb",
        "frame_0012.vdb", "final.tfxc", "shard.toml", "checkpoint_000012.tfxc"})
    ASSERT_TRUE(fs::remove(s1 / name)) << name;
  const Result unfinished = merge(3);
  EXPECT_EQ(unfinished.exit, 2);
  EXPECT_NE(unfinished.err.find(s1.string() + ": error: not a finished shard's folder"),
            std::string::npos)
      << unfinished.err;
  // Another shard's checkpoint is refused.
  const Result wrong = run(effect + " " + options + " --shard 1/3 --out " + s1.string() +
                           " --resume " + shardDir(3, 0) + "/checkpoint_000006.tfxc");
  EXPECT_EQ(wrong.exit, 2);
  EXPECT_NE(wrong.err.find("checkpoint is of shard 0/3 (expected shard 1/3)"), std::string::npos)
      << wrong.err;
  const Result resumed = run(effect + " " + options + " --shard 1/3 --out " + s1.string() +
                             " --quiet --resume " + (s1 / "checkpoint_000006.tfxc").string());
  ASSERT_EQ(resumed.exit, 0) << resumed.err;
  const Result r = merge(3);
  ASSERT_EQ(r.exit, 0) << r.err;
  EXPECT_EQ(hashOf(r), whole);
  expectSameFiles(path("3/merged"));
}

// What cannot be sharded exactly is refused with exit 2, naming why; nothing is written.
TEST_F(Shards, EffectsThatCannotBeShardedAreRefused) {
  Result r = run("run samples/fireworks.toml --frames 2 --shard 0/2 --out " + path("f"));
  EXPECT_EQ(r.exit, 2);
  EXPECT_EQ(r.err,
            "samples/fireworks.toml: error: cannot shard: emitter 'sparks' emits at the events of "
            "'shells': a child's id counts the events of every shard before it, which no shard "
            "knows alone (run this effect unsharded)\n");
  // The fountain makes 2000 drops a second that live up to 3 s: in a 3 s run the bound, from the
  // schedule and the longest lifetime, is 6016 (two frames would never reach the cap).
  r = run("run samples/fountain.toml --seconds 3 --shard 0/2 --out " + path("f") +
          " --set simulation.max_particles=1500");
  EXPECT_EQ(r.exit, 2);
  EXPECT_NE(r.err.find("samples/fountain.toml: error: cannot shard: simulation.max_particles = "
                       "1500 may bind: up to 6016 particles"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("a cap is a count over every shard"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(path("f")));
  r = run("run samples/fountain.toml --shard 2/2");
  EXPECT_EQ(r.exit, 2);
  EXPECT_EQ(r.err, "tickfx run: --shard: '2/2': index 2 is not below the count 2\n");
  r = run("run samples/fountain.toml --shard two");
  EXPECT_EQ(r.exit, 2);
  EXPECT_EQ(r.err, "tickfx run: --shard: 'two' is not I/N (shard I of N, from 0)\n");
}

// Shards that do not belong together are refused by name, before anything is merged.
TEST_F(Shards, MergeRefusesShardsThatDoNotBelongTogether) {
  const std::string options = "--frames 3 --format csv --quiet";
  const auto shard = [&](const std::string& effect, const std::string& spec, const std::string& out,
                         const std::string& extra = "") {
    const Result r = run("run samples/" + effect + ".toml " + options + " --shard " + spec +
                         " --out " + path(out) + " " + extra);
    ASSERT_EQ(r.exit, 0) << r.err;
  };
  shard("fountain", "0/2", "a0");
  shard("fountain", "1/2", "a1");
  shard("leaves", "1/2", "leaves1");
  shard("fountain", "1/2", "seed1", "--set simulation.seed=8");
  shard("fountain", "1/3", "third");
  const auto refused = [&](const std::string& dirs, const std::string& message) {
    const Result r = run("merge " + dirs + " --out " + path("m"));
    EXPECT_EQ(r.exit, 2) << dirs;
    EXPECT_NE(r.err.find(message), std::string::npos) << r.err;
  };
  refused(path("a0") + " " + path("leaves1"),
          path("leaves1") + ": error: a shard of another effect: effect hash ");
  refused(path("a0") + " " + path("seed1"),
          path("seed1") + ": error: a shard of another effect: effect hash ");
  refused(
      path("a0") + " " + path("third"),
      path("third") + ": error: shard 1/3 of a run in 3 shards (" + path("a0") + " has shard 0/2)");
  refused(path("a0"), path("a0") + ": error: shard 1/2 is missing (1 of 2 shard folders given)");
  refused(path("a0") + " " + path("a0"), path("a0") + ": error: shard 0/2, as is " + path("a0"));
  fs::remove(path("a1") + "/frame_0002.csv");
  refused(path("a0") + " " + path("a1"),
          path("a1") + "/frame_0002.csv: error: missing (frame 2 of shard 1/2)");
  refused(path("nowhere"), path("nowhere") + ": error: not a folder");
}

}  // namespace
