// `tickfx determinism --record` and `--compare`: a hash log made on one machine, compared on
// another (here: the same one, with the log edited where a real farm's would differ).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "CliTestSupport.h"
#include "io/state/Checkpoint.h"
#include "particles/StateHash.h"

namespace {

using tickfx::cli_test::readAll;
using tickfx::cli_test::Result;

class HashLog : public tickfx::cli_test::CliFixture {
 protected:
  HashLog() : CliFixture("tickfx_hash_log") {}

  Result run(const std::string& args) const { return runProgram(TICKFX_CLI, args); }

  static std::vector<std::string> lines(const std::string& text) {
    std::vector<std::string> out;
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);) out.push_back(line);
    return out;
  }
  void writeLines(const std::string& name, const std::vector<std::string>& text) const {
    std::ofstream out(dir_ / name);
    for (const std::string& line : text) out << line << '\n';
  }
  // The index of the first line starting with `prefix`, or -1.
  static int find(const std::vector<std::string>& text, const std::string& prefix) {
    for (std::size_t i = 0; i < text.size(); ++i) {
      if (text[i].rfind(prefix, 0) == 0) return static_cast<int>(i);
    }
    return -1;
  }
  static std::vector<std::string> fields(const std::string& line) {
    std::vector<std::string> out;
    std::istringstream in(line);
    for (std::string f; in >> f;) out.push_back(f);
    return out;
  }
  // "state-hash: H" of a plain run.
  std::string plainHash(const std::string& args) const {
    const Result r = run("run " + args + " --format none --hash");
    const std::size_t at = r.out.find("state-hash: ");
    return at == std::string::npos ? "no hash: " + r.out + r.err : r.out.substr(at + 12, 16);
  }
};

TEST_F(HashLog, ALogComparedWithItselfIsIdentical) {
  const Result rec =
      run("determinism samples/fountain.toml --seconds 1 --fps 30 --record " + path("a.log"));
  ASSERT_EQ(rec.exit, 0) << rec.out << rec.err;
  const std::string hash = plainHash("samples/fountain.toml --seconds 1 --fps 30");
  EXPECT_EQ(rec.out.rfind("recorded " + path("a.log") +
                              ": 120 ticks at 120 Hz, 30 frames, "
                              "state-hash " +
                              hash + ", 0 snapshot(s)\n",
                          0),
            0u)
      << rec.out;

  const std::vector<std::string> log = lines(readAll(path("a.log")));
  ASSERT_GT(log.size(), 16u);
  EXPECT_EQ(log[0], "tickfx hash log 1");
  for (const char* key : {"machine: ", "cpu: ", "compiler: ", "build: ", "tickfx: 0.3.0"})
    EXPECT_GE(find(log, key), 0) << key;
  EXPECT_EQ(log[find(log, "seed: ")], "seed: 7");
  EXPECT_EQ(log[find(log, "step_rate: ")], "step_rate: 120");
  EXPECT_EQ(log[find(log, "fps: ")], "fps: 30/1");
  EXPECT_EQ(log[find(log, "fingerprint: ")],
            "fingerprint: " + tickfx::hashToHex(tickfx::io::effectFileFingerprint(
                                  TICKFX_SOURCE_DIR "/samples/fountain.toml", {})));
  // The last tick's line holds the plain run's hash; its frame comes right after it.
  const int last = find(log, "tick 120 ");
  ASSERT_GE(last, 0);
  EXPECT_EQ(fields(log[last])[2], hash);
  EXPECT_EQ(fields(log[last]).size(), 3 + fields(log[find(log, "columns: ")]).size() - 1);
  EXPECT_EQ(log[last + 1].rfind("frame 30 120 ", 0), 0u) << log[last + 1];
  EXPECT_EQ(log.back(), "end");

  const Result cmp = run("determinism samples/fountain.toml --compare " + path("a.log"));
  EXPECT_EQ(cmp.exit, 0) << cmp.out << cmp.err;
  EXPECT_NE(cmp.out.find("\nidentical through tick 120 and frame 30 (state-hash " + hash + ")\n"),
            std::string::npos)
      << cmp.out;
  EXPECT_EQ(cmp.err, "");
}

TEST_F(HashLog, AnEditedHashReportsItsTick) {
  ASSERT_EQ(run("determinism samples/burst.toml --seconds 1 --record " + path("a.log")).exit, 0);
  std::vector<std::string> log = lines(readAll(path("a.log")));
  const int line = find(log, "tick 37 ");
  ASSERT_GE(line, 0);
  std::vector<std::string> f = fields(log[line]);
  const std::string original = f[2];
  f[2] = original == "0123456789abcdef" ? "fedcba9876543210" : "0123456789abcdef";
  std::string edited = "tick";
  for (std::size_t i = 1; i < f.size(); ++i) edited += " " + f[i];
  log[line] = edited;
  writeLines("b.log", log);

  const Result r = run("determinism samples/burst.toml --compare " + path("b.log"));
  EXPECT_EQ(r.exit, 1) << r.out << r.err;
  EXPECT_NE(r.out.find("\nthe runs part at tick 37 (t = 0.308333333 s): state-hash " + original +
                       " here, " + f[2] +
                       " in the log\n"
                       "columns that differ: -\n"
                       "the log holds no state of tick 37: record it again with --snapshot-at 37 "
                       "to name the particle and both values\n"),
            std::string::npos)
      << r.out;
}

// A real difference, as another machine's log would show it: one float of one particle, so its
// column's hash and the state hash differ too. The snapshot names the particle and both values.
TEST_F(HashLog, ASnapshotNamesTheParticleColumnAndBothValues) {
  ASSERT_EQ(run("determinism samples/burst.toml --seconds 1 --snapshot-at 37,200 --record " +
                path("a.log"))
                .exit,
            0);
  std::vector<std::string> log = lines(readAll(path("a.log")));
  const std::vector<std::string> columns = fields(log[find(log, "columns: ")]);
  ASSERT_EQ(columns[1], "counters");
  ASSERT_EQ(columns[5], "position.y");  // columns: counters id birth_tick position.x position.y
  const int tick = find(log, "tick 37 ");
  const int snapshot = find(log, "snapshot 37 ");
  ASSERT_EQ(snapshot, tick + 1);
  ASSERT_GE(std::stoi(fields(log[snapshot])[2]), 3);
  EXPECT_EQ(find(log, "snapshot 200"), -1) << "past the end: ignored";
  // Row 2 (the third particle), position.y: the first value is the row's word "row".
  std::vector<std::string> row = fields(log[snapshot + 3]);
  const std::string id = row[1];
  const std::string before = row[4];
  row[4] = before == "3f800000" ? "3f800001" : "3f800000";
  std::string text = "row";
  for (std::size_t i = 1; i < row.size(); ++i) text += " " + row[i];
  log[snapshot + 3] = text;
  std::vector<std::string> t = fields(log[tick]);
  t[2] = "0000000000000000";      // the state hash
  t[3 + 4] = "0000000000000000";  // position.y's column hash (after "tick", N, the state hash)
  text = "tick";
  for (std::size_t i = 1; i < t.size(); ++i) text += " " + t[i];
  log[tick] = text;
  writeLines("b.log", log);

  const Result r = run("determinism samples/burst.toml --compare " + path("b.log"));
  EXPECT_EQ(r.exit, 1) << r.out << r.err;
  EXPECT_NE(r.out.find("\ncolumns that differ: position.y\n"), std::string::npos) << r.out;
  const std::string value = "0x" + before + " (";
  const std::string expected = "first difference: particle id " +
                               std::to_string(std::stoull(id, nullptr, 16)) +
                               ", position.y: " + value;
  EXPECT_NE(r.out.find(expected), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(" here, 0x" + row[4] + " ("), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(" in the log\n"), std::string::npos) << r.out;
}

TEST_F(HashLog, ALogOfAnotherEffectSeedOrStepRateIsRefused) {
  ASSERT_EQ(run("determinism samples/fountain.toml --seconds 0.5 --record " + path("a.log")).exit,
            0);
  const std::string log = path("a.log");
  const auto fp = [](const std::string& effect, const std::vector<std::string>& overrides) {
    return tickfx::hashToHex(
        tickfx::io::effectFileFingerprint(TICKFX_SOURCE_DIR "/" + effect, overrides));
  };
  const std::string fountain = fp("samples/fountain.toml", {});

  // The same seed and step rate as fountain.toml, another effect: named by its fingerprint. A
  // copy with one more comment line is another file, and so is an override.
  const std::string copy = path("copy.toml");
  std::ofstream(copy) << readAll(TICKFX_SOURCE_DIR "/samples/fountain.toml") << "# a copy\n";
  Result r = run("determinism " + copy + " --compare " + log);
  EXPECT_EQ(r.exit, 2) << r.out << r.err;
  EXPECT_EQ(r.err, log + ": error: the log is of another effect (fingerprint " + fountain +
                       ", this run " +
                       tickfx::hashToHex(tickfx::io::effectFileFingerprint(copy, {})) + ")\n");
  r = run("determinism samples/fountain.toml --set forces.1.k=0.3 --compare " + log);
  EXPECT_EQ(r.exit, 2) << r.out << r.err;
  EXPECT_EQ(r.err, log + ": error: the log is of another effect (fingerprint " + fountain +
                       ", this run " + fp("samples/fountain.toml", {"forces.1.k=0.3"}) + ")\n");

  r = run("determinism samples/fountain.toml --set simulation.seed=8 --compare " + log);
  EXPECT_EQ(r.exit, 2);
  EXPECT_EQ(r.err, log + ": error: the log is of another seed (7, this run 8)\n");

  r = run("determinism samples/fountain.toml --set simulation.step_rate=240 --compare " + log);
  EXPECT_EQ(r.exit, 2);
  EXPECT_EQ(r.err, log + ": error: the log is of another step rate (120 Hz, this run 240 Hz)\n");
  EXPECT_EQ(r.out, "");
}

TEST_F(HashLog, ALogOfAVersionThatHashedOtherwiseIsRefused) {
  ASSERT_EQ(run("determinism samples/fountain.toml --seconds 0.5 --record " + path("a.log")).exit,
            0);
  // The same log as tickfx 0.2.0 wrote it: its hashes are of the same states, by the definition
  // before columns were hashed in blocks.
  std::string text = readAll(path("a.log"));
  const std::size_t at = text.find("tickfx: 0.3.0\n");
  ASSERT_NE(at, std::string::npos) << text.substr(0, 400);
  text.replace(at, 14, "tickfx: 0.2.0\n");
  const std::string old = path("old.log");
  std::ofstream(old) << text;
  const Result r = run("determinism samples/fountain.toml --compare " + old);
  EXPECT_EQ(r.exit, 2) << r.out << r.err;
  EXPECT_EQ(r.err, old +
                       ": error: the log is of tickfx 0.2.0, whose state hashes are defined "
                       "otherwise (since 0.3.0 each column is hashed in blocks); record it again "
                       "with this build\n");
}

TEST_F(HashLog, TruncatedOrGarbledLogsAreRefusedWithFileAndLine) {
  ASSERT_EQ(run("determinism samples/fountain.toml --seconds 0.5 --record " + path("a.log")).exit,
            0);
  const std::vector<std::string> log = lines(readAll(path("a.log")));
  const int tick9 = find(log, "tick 9 ");
  ASSERT_GT(tick9, 0);

  // Cut after tick 9's line: the error is at the line after the last one.
  writeLines("cut.log", std::vector<std::string>(log.begin(), log.begin() + tick9 + 1));
  Result r = run("determinism samples/fountain.toml --compare " + path("cut.log"));
  EXPECT_EQ(r.exit, 2);
  EXPECT_EQ(r.err, path("cut.log") + ":" + std::to_string(tick9 + 2) +
                       ": error: the log ends without its 'end' line (truncated? 9 of 60 ticks)\n");

  // A hash that is not hex.
  std::vector<std::string> bad = log;
  std::vector<std::string> f = fields(bad[tick9]);
  bad[tick9] = "tick 9 zz" + f[2].substr(2);
  for (std::size_t i = 3; i < f.size(); ++i) bad[tick9] += " " + f[i];
  writeLines("bad.log", bad);
  r = run("determinism samples/fountain.toml --compare " + path("bad.log"));
  EXPECT_EQ(r.exit, 2);
  EXPECT_EQ(r.err, path("bad.log") + ":" + std::to_string(tick9 + 1) + ": error: tick 9: 'zz" +
                       f[2].substr(2) + "' is not 16 lowercase hex digits\n");

  // A tick line missing.
  bad = log;
  bad.erase(bad.begin() + tick9);
  writeLines("gap.log", bad);
  r = run("determinism samples/fountain.toml --compare " + path("gap.log"));
  EXPECT_EQ(r.exit, 2);
  EXPECT_EQ(r.err, path("gap.log") + ":" + std::to_string(tick9 + 1) +
                       ": error: tick 10 out of order (expected tick 9 of 60)\n");

  // Not a log at all.
  writeLines("other.log", {"tick,state_hash", "1,0123456789abcdef"});
  r = run("determinism samples/fountain.toml --compare " + path("other.log"));
  EXPECT_EQ(r.exit, 2);
  EXPECT_EQ(r.err, path("other.log") +
                       ":1: error: not a tickfx hash log: 'tick,state_hash' (expected 'tickfx "
                       "hash log 1')\n");
}

TEST_F(HashLog, UsageErrorsExitTwo) {
  EXPECT_EQ(run("determinism samples/fountain.toml --record a --compare b").exit, 2);
  EXPECT_EQ(run("determinism samples/fountain.toml --compare a --seconds 2").exit, 2);
  EXPECT_EQ(run("determinism samples/fountain.toml --record a --threads 2").exit, 2);
  const Result r = run("determinism samples/fountain.toml --record " + path("no/such/dir/a.log"));
  EXPECT_EQ(r.exit, 2);
  EXPECT_FALSE(std::filesystem::exists(path("no")));
}

}  // namespace
