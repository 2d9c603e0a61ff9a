// `tickfx run --format vdb` and the file emitter as a user runs them: the VDB caches hold what
// the CSV caches of the same run hold, vdb_print lists them with their point counts, and an
// effect can be seeded from a cache. Everything is written into the test's own directory.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include "CliTestSupport.h"
#include "PointCacheTestSupport.h"
#include "io/cache/CsvCache.h"
#include "io/cache/UsdaReader.h"
#include "io/cache/VdbPointCache.h"

namespace fs = std::filesystem;

namespace {

using tickfx::cli_test::Result;

class CliPoints : public tickfx::cli_test::CliFixture {
 protected:
  CliPoints() : CliFixture("tickfx_cli_points") {}

  Result run(const std::string& program, const std::string& args) const {
    return runProgram(program, args);
  }
  Result tickfx(const std::string& args) const { return run(TICKFX_CLI, args); }
};

TEST_F(CliPoints, RunWritesVdbCachesHoldingTheCsvCachesBits) {
  const Result r =
      tickfx("run samples/fountain.toml --frames 3 --format vdb,csv --out " + path("c"));
  ASSERT_EQ(r.exit, 0) << r.err;
  for (int f = 1; f <= 3; ++f) {
    const std::string name = path("c/frame_000" + std::to_string(f));
    const tickfx::io::FrameData csv = tickfx::io::readCsvCache(name + ".csv");
    tickfx::io::VdbCacheContents contents;
    const tickfx::io::FrameData vdb = tickfx::io::readVdbPointCache(name + ".vdb", &contents);
    ASSERT_GT(csv.size(), 0u);
    ASSERT_EQ(vdb.size(), csv.size());
    EXPECT_EQ(vdb.id, csv.id);
    for (int c = 0; c < 3; ++c) {
      EXPECT_EQ(0, std::memcmp(vdb.position[c].data(), csv.position[c].data(), csv.size() * 4));
      EXPECT_EQ(0, std::memcmp(vdb.velocity[c].data(), csv.velocity[c].data(), csv.size() * 4));
    }
    EXPECT_EQ(0, std::memcmp(vdb.age.data(), csv.age.data(), csv.size() * 4));
    EXPECT_EQ(0, std::memcmp(vdb.life.data(), csv.life.data(), csv.size() * 4));
    EXPECT_EQ(0, std::memcmp(vdb.mass.data(), csv.mass.data(), csv.size() * 4));
    EXPECT_EQ(vdb.frame, f);
    EXPECT_EQ(vdb.timeSeconds, f / 24.0);
    // samples/fountain.toml: seed 7, 120 Hz, the default integrator.
    EXPECT_TRUE(std::regex_match(contents.metadata.effectHash, std::regex("[0-9a-f]{16}")))
        << contents.metadata.effectHash;
    EXPECT_EQ(contents.metadata.seed, 7u);
    EXPECT_EQ(contents.metadata.stepRateHz, 120);
    EXPECT_EQ(contents.metadata.integrator, "semi_implicit_euler");
    EXPECT_EQ(contents.metadata.tickfxVersion, TICKFX_VERSION);
  }
  // The same effect, overridden, is another effect: another hash in the caches.
  ASSERT_EQ(tickfx("run samples/fountain.toml --frames 1 --format vdb --set simulation.seed=7 "
                   "--out " +
                   path("d"))
                .exit,
            0);
  tickfx::io::VdbCacheContents a, b;
  tickfx::io::readVdbPointCache(path("c/frame_0001.vdb"), &a);
  tickfx::io::readVdbPointCache(path("d/frame_0001.vdb"), &b);
  EXPECT_NE(a.metadata.effectHash, b.metadata.effectHash);
}

// --format usda: one layer a run, DIR/EFFECT.usda, a time sample a frame holding the VDB caches'
// bits; a run that cannot write it whole (one resumed) refuses before the first tick.
TEST_F(CliPoints, RunWritesOneUsdaLayerHoldingTheVdbCachesBits) {
  const Result r = tickfx(
      "run samples/fireworks.toml --frames 3 --fps 1000/1001 "
      "--format vdb,usda --out " +
      path("u"));
  ASSERT_EQ(r.exit, 0) << r.err;
  EXPECT_NE(r.out.find("usd layer: " + path("u/fireworks.usda") + " (time codes 1 to 3)"),
            std::string::npos)
      << r.out;
  EXPECT_FALSE(fs::exists(path("u/fireworks.usda.parts")));
  EXPECT_EQ(tickfx::io::usdaFrames(path("u/fireworks.usda")), (std::vector<std::int64_t>{1, 2, 3}));
  std::ifstream in(path("u/fireworks.usda"));
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("    timeCodesPerSecond = 0.999000999000999\n"), std::string::npos);
  for (int f = 1; f <= 3; ++f) {
    const tickfx::io::FrameData vdb =
        tickfx::io::readVdbPointCache(path("u/frame_000" + std::to_string(f) + ".vdb"));
    const tickfx::io::FrameData usda = tickfx::io::readUsdaFrame(path("u/fireworks.usda"), f);
    ASSERT_GT(usda.size(), 0u);
    EXPECT_EQ(usda.attributeNames, vdb.attributeNames);
    EXPECT_EQ(tickfx::io::frameHash(usda), tickfx::io::frameHash(vdb)) << "frame " << f;
  }
  ASSERT_EQ(tickfx("run samples/burst.toml --frames 2 --format csv --checkpoint-every 1 --out " +
                   path("k"))
                .exit,
            0);
  const Result resumed = tickfx("run samples/burst.toml --frames 3 --format usda --resume " +
                                path("k/checkpoint_000002.tfxc") + " --out " + path("k"));
  EXPECT_EQ(resumed.exit, 2);
  EXPECT_NE(resumed.err.find("--resume cannot continue a .usda layer"), std::string::npos)
      << resumed.err;
  EXPECT_FALSE(fs::exists(path("k/burst.usda")));
}

TEST_F(CliPoints, UnknownFormatsNameVdb) {
  const Result r = tickfx("run samples/fountain.toml --frames 1 --format vdbs --out " + path("c"));
  EXPECT_EQ(r.exit, 2);
  EXPECT_NE(r.err.find("unknown format 'vdbs' (expected csv, ply, vdb, usda or none)"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(path("c")));
  // In the effect file too.
  std::ofstream(path("fx.toml")) << "format_version = 1\n[simulation]\nstep_rate = 60\n"
                                    "[[emitters]]\nrate = 10\n[output]\nformats = [\"vdb\"]\n";
  EXPECT_EQ(tickfx("check " + path("fx.toml")).exit, 0);
  ASSERT_EQ(tickfx("run " + path("fx.toml") + " --frames 2 --out " + path("e")).exit, 0);
  EXPECT_TRUE(fs::exists(path("e/frame_0002.vdb")));
  EXPECT_FALSE(fs::exists(path("e/frame_0002.csv")));
}

// vdb_print (OpenVDB's own tool) lists the grid "points" of each cache, and the point count
// from its metadata, which is the number of rows of the CSV cache of the same frame and the
// run's final particle count.
TEST_F(CliPoints, VdbPrintListsThePointsGridWithItsPointCount) {
  // TICKFX_VDB_PRINT is what find_program found at configure time: VDB_PRINT-NOTFOUND without it.
  const std::string vdbPrint = TICKFX_VDB_PRINT;
  ASSERT_FALSE(vdbPrint.empty() || vdbPrint.ends_with("-NOTFOUND"))
      << "vdb_print was not found when the build was configured (" << vdbPrint
      << "): install libopenvdb-tools (scripts/common.sh installs it) and configure again";
  const Result r =
      tickfx("run samples/fountain.toml --frames 3 --format vdb,csv --out " + path("c"));
  ASSERT_EQ(r.exit, 0) << r.err;
  std::smatch alive;
  ASSERT_TRUE(std::regex_search(r.out, alive, std::regex("particles alive: ([0-9]+)"))) << r.out;
  for (int f = 1; f <= 3; ++f) {
    const std::string vdb = path("c/frame_000" + std::to_string(f) + ".vdb");
    const Result listing = run(vdbPrint, "-m '" + vdb + "'");
    ASSERT_EQ(listing.exit, 0) << listing.err;
    // "points      ptdataidx32 (0,0,0)->(0,1,0) ..." then the grid's metadata.
    EXPECT_TRUE(std::regex_search(listing.out, std::regex("(^|\n)points +ptdataidx32 ")))
        << listing.out;
    std::smatch count;
    ASSERT_TRUE(std::regex_search(listing.out, count, std::regex("tickfx_point_count: ([0-9]+)")))
        << listing.out;
    const auto rows = tickfx::io::readCsvCache(path("c/frame_000" + std::to_string(f) + ".csv"));
    EXPECT_EQ(std::stoul(count[1].str()), rows.size()) << "frame " << f;
    if (f == 3) {
      EXPECT_EQ(count[1].str(), alive[1].str());
    }
    EXPECT_NE(listing.out.find("tickfx_frame: " + std::to_string(f)), std::string::npos);
    EXPECT_NE(listing.out.find("tickfx_integrator: semi_implicit_euler"), std::string::npos);
    EXPECT_NE(listing.out.find("tickfx_step_rate: 120"), std::string::npos);
    EXPECT_NE(listing.out.find("tickfx_seed: 7"), std::string::npos);
  }
}

TEST_F(CliPoints, AnEffectSeededFromACacheChecksAndRuns) {
  ASSERT_EQ(tickfx("run samples/fountain.toml --frames 3 --format vdb,csv --out " + path("c")).exit,
            0);
  const auto rows = tickfx::io::readCsvCache(path("c/frame_0003.csv")).size();
  for (const char* file : {"c/frame_0003.vdb", "c/frame_0003.csv"}) {
    std::ofstream(path("fx.toml")) << "format_version = 1\n[simulation]\nstep_rate = 60\n"
                                      "[[emitters]]\ntype = \"file\"\nfile = \""
                                   << file << "\"\n[[forces]]\ntype = \"gravity\"\n";
    const Result check = tickfx("check " + path("fx.toml"));
    EXPECT_EQ(check.exit, 0) << check.err;
    const Result r = tickfx("run " + path("fx.toml") + " --frames 2 --format none");
    ASSERT_EQ(r.exit, 0) << r.err;
    EXPECT_NE(r.out.find("particles alive: " + std::to_string(rows) + " "), std::string::npos)
        << r.out;
  }
  // A missing points file is an effect error: exit 2, nothing written.
  std::ofstream(path("fx.toml")) << "format_version = 1\n[simulation]\nstep_rate = 60\n"
                                    "[[emitters]]\ntype = \"file\"\nfile = \"nope.vdb\"\n";
  const Result r = tickfx("run " + path("fx.toml") + " --frames 2 --out " + path("o"));
  EXPECT_EQ(r.exit, 2);
  EXPECT_NE(r.err.find(path("fx.toml") + ":6:8: error: emitters.0.file: no such file \"" +
                       path("nope.vdb") + "\""),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(path("o")));
}

TEST_F(CliPoints, ACorruptPointsFileIsAnEffectErrorNotACrash) {
  // A one-point cache whose first attribute array (P) says it holds 13 bytes, one too many: the
  // paged stream of OpenVDB 10 asserted on it, so `check` and `run` died of SIGABRT (exit 134).
  tickfx::io::writeVdbPointCache(tickfx::test::onePointFrame(), tickfx::io::VdbCacheMetadata{},
                                 path("pts.vdb"), tickfx::test::kPagedArrays);
  const std::size_t at = tickfx::test::overstateFirstAttributeArray(path("pts.vdb"));
  ASSERT_NE(at, std::string::npos);
  std::ofstream(path("fx.toml")) << "format_version = 1\n[simulation]\nstep_rate = 60\n"
                                    "[[emitters]]\ntype = \"file\"\nfile = \"pts.vdb\"\n";
  const std::string message =
      path("fx.toml") + ":6:8: error: emitters.0.file: \"" + path("pts.vdb") +
      "\" cannot be read: " + path("pts.vdb") +
      ": grid 'points': cannot read the grid (the file is corrupt at byte " + std::to_string(at) +
      ": an attribute array of 13 bytes where 12 are expected)";
  const Result check = tickfx("check " + path("fx.toml"));
  EXPECT_EQ(check.exit, 2) << check.err;
  EXPECT_NE(check.err.find(message), std::string::npos) << check.err;
  const Result r = tickfx("run " + path("fx.toml") + " --frames 2 --out " + path("o"));
  EXPECT_EQ(r.exit, 2) << r.err;
  EXPECT_NE(r.err.find(message), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(path("o")));
}

}  // namespace
