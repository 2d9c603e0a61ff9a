// The file emitter in effect files ([[emitters]] type = "file"): particles born at the points of
// a CSV cache or a VDB points file, and the parser's messages. (The core's PointListShape is
// tested in test_emitter.cpp.) Files are written into a temporary directory of the test and
// removed afterwards.
#include <gtest/gtest.h>
#include <unistd.h>

#include <bit>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "VdbTestData.h"
#include "io/cache/CsvCache.h"
#include "io/cache/VdbPointCache.h"
#include "io/effect/EffectBuilder.h"
#include "io/effect/EffectParser.h"
#include "particles/Emitter.h"
#include "particles/ParticleSystem.h"
#include "tests/support/FileBytes.h"

namespace tickfx {
namespace {

namespace fs = std::filesystem;

constexpr float kDenormal = std::numeric_limits<float>::denorm_min();

std::uint32_t bits(float x) { return std::bit_cast<std::uint32_t>(x); }

void expectSameBits(const Eigen::Vector3f& got, const Eigen::Vector3f& want,
                    const std::string& what) {
  for (int c = 0; c < 3; ++c) EXPECT_EQ(bits(got[c]), bits(want[c])) << what << " component " << c;
}

// ---- effect files: [[emitters]] type = "file" --------------------------------------------------

class ioFileEmitter : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("tickfx_file_emitter_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  // Seven points with odd bits (−0.0, a denormal), velocities, ids out of order of position.
  static io::FrameData points() {
    io::FrameData f;
    const Eigen::Index n = 7;
    f.position.resize(n);
    f.velocity.resize(n);
    f.age = FloatColumn::Constant(n, 0.5f);
    f.life = FloatColumn::Constant(n, 3.0f);
    f.mass = FloatColumn::Constant(n, 2.0f);
    for (Eigen::Index i = 0; i < n; ++i) {
      f.id.push_back(static_cast<std::uint64_t>(10 + 3 * i));
      for (int c = 0; c < 3; ++c) {
        f.position[c][i] = static_cast<float>(i) * 0.37f - static_cast<float>(c) * 1.1f;
        f.velocity[c][i] = static_cast<float>(c) - 0.25f * static_cast<float>(i);
      }
    }
    f.position.y[0] = -0.0f;
    f.position.z[1] = kDenormal;
    return f;
  }
  static Eigen::Vector3f row(const Vec3Column& c, Eigen::Index i) {
    return {c.x[i], c.y[i], c.z[i]};
  }

  // The diagnostics of `toml` written as fx.toml in the test's directory, formatted.
  std::vector<std::string> errors(const std::string& toml,
                                  const std::vector<std::string>& overrides = {}) const {
    std::ofstream(path("fx.toml")) << toml;
    const io::LoadResult r = io::loadEffectFile(path("fx.toml"), overrides);
    std::vector<std::string> out;
    for (const io::Diagnostic& d : r.diagnostics) out.push_back(d.format());
    if (!out.empty()) {
      EXPECT_FALSE(r.ok());
    }
    return out;
  }
  io::EffectSettings load(const std::string& toml, const std::string& where = "fx.toml") const {
    fs::create_directories(fs::path(path(where)).parent_path());
    std::ofstream(path(where)) << toml;
    const io::LoadResult r = io::loadEffectFile(path(where));
    for (const io::Diagnostic& d : r.diagnostics) ADD_FAILURE() << d.format();
    if (!r.ok()) throw std::runtime_error("effect did not load");
    return *r.effect;
  }

  fs::path dir_;
};

const std::string kHead = "format_version = 1\n[simulation]\nstep_rate = 10\nseed = 3\n";

// The particles one emitter makes in `ticks` ticks, by birth, and how many each tick made.
struct Births {
  std::vector<ParticleInit> particles;
  std::vector<std::uint64_t> perTick;
};
Births births(const EmitterSettings& settings, std::int64_t ticks) {
  const Emitter e(settings, 0, 10);
  Births b;
  for (std::int64_t t = 0; t < ticks; ++t) {
    const std::uint64_t first = e.serialBefore(t), last = e.serialBefore(t + 1);
    b.perTick.push_back(last - first);
    for (std::uint64_t s = first; s < last; ++s) b.particles.push_back(e.sample(3, s));
  }
  return b;
}

TEST_F(ioFileEmitter, ACsvCacheSpawnsExactlyItsPointsInOneBurstAtStart) {
  const io::FrameData f = points();
  io::writeCsvCache(f, path("pts.csv"));
  const io::EffectSettings effect =
      load(kHead + "[[emitters]]\ntype = \"file\"\nfile = \"pts.csv\"\nstart = 0.25\n");
  ASSERT_EQ(effect.emitters.size(), 1u);
  EXPECT_EQ(effect.emitters[0].name, "file_0");
  // Neither rate nor bursts: one burst of every point at start (tick 3 at 10 Hz).
  const Births b = births(effect.emitters[0], 6);
  EXPECT_EQ(b.perTick, (std::vector<std::uint64_t>{0, 0, 0, 7, 0, 0}));
  ASSERT_EQ(b.particles.size(), 7u);
  for (Eigen::Index i = 0; i < 7; ++i) {
    const ParticleInit& p = b.particles[static_cast<std::size_t>(i)];
    expectSameBits(p.position, row(f.position, i), "position " + std::to_string(i));
    expectSameBits(p.velocity, row(f.velocity, i), "velocity " + std::to_string(i));
    EXPECT_EQ(p.mass, 1.0f);  // the emitter's, not the file's
  }
  // Through the whole system: seven particles after the burst.
  const auto system = io::buildSystem(effect);
  system->stepTicks(4);
  EXPECT_EQ(system->pool().size(), 7u);
}

TEST_F(ioFileEmitter, AVdbFileSpawnsExactlyItsPointsAndARateCyclesThroughThem) {
  const io::FrameData f = points();
  io::writeVdbPointCache(f, io::VdbCacheMetadata{}, path("pts.vdb"));
  // The file relative to the effect file, wherever the command runs.
  const io::EffectSettings effect = load(kHead + R"([[emitters]]
type = "file"
name = "cloud"
file = "../pts.vdb"
rate = 20
lifetime = 5
mass = 0.5
)",
                                         "effects/fx.toml");
  const Births b = births(effect.emitters[0], 5);
  EXPECT_EQ(b.perTick, (std::vector<std::uint64_t>{2, 2, 2, 2, 2}));
  ASSERT_EQ(b.particles.size(), 10u);
  for (std::size_t s = 0; s < b.particles.size(); ++s) {
    const auto k = static_cast<Eigen::Index>(s % 7);
    expectSameBits(b.particles[s].position, row(f.position, k), "serial " + std::to_string(s));
    expectSameBits(b.particles[s].velocity, row(f.velocity, k), "serial " + std::to_string(s));
    EXPECT_EQ(b.particles[s].mass, 0.5f);
    EXPECT_EQ(b.particles[s].lifetime, 5.0f);
  }
}

TEST_F(ioFileEmitter, BurstsAndAnOffsetAndAFileWithoutVelocities) {
  // A VDB file as another tool writes it: positions only, so the emitter's speed applies.
  vdb_test::PointsFileSpec bare;
  bare.positions = {{0.0, 1.0, 2.0}, {-1.0, 0.0, 0.5}};
  bare.voxelSize = 1.0;
  bare.codec = vdb_test::PositionCodec::Null;
  vdb_test::writePointsFile(path("bare.vdb"), bare);

  const io::EffectSettings effect = load(kHead + R"([[emitters]]
type = "file"
file = "bare.vdb"
position = [10.0, 0.0, 0.0]
bursts = [{ time = 0.1, count = 3 }, { time = 0.3, count = 2 }]
direction = [0.0, 0.0, 1.0]
speed = 4.0
)");
  const Births b = births(effect.emitters[0], 5);
  EXPECT_EQ(b.perTick, (std::vector<std::uint64_t>{0, 3, 0, 2, 0}));
  ASSERT_EQ(b.particles.size(), 5u);
  // File order: OpenVDB's (voxel by voxel); the rows are read back as the file holds them.
  const io::FrameData read = io::readVdbPointCache(path("bare.vdb"));
  for (std::size_t s = 0; s < 5; ++s) {
    const auto k = static_cast<Eigen::Index>(s % 2);
    const Eigen::Vector3f want =
        Eigen::Vector3f(Eigen::Vector3f(10.0f, 0.0f, 0.0f) + row(read.position, k));
    expectSameBits(b.particles[s].position, want, "serial " + std::to_string(s));
    EXPECT_EQ(b.particles[s].velocity, Eigen::Vector3f(0.0f, 0.0f, 4.0f));
  }
}

std::string expectedFile(const std::string& detail = "") {
  return "(expected a points file relative to the effect file: .vdb (OpenVDB points, grid "
         "\"points\") or .csv (a tickfx CSV cache)" +
         detail + ")";
}

TEST_F(ioFileEmitter, MissingUnknownEmptyAndBrokenFilesAreErrorsNamingTheFile) {
  const std::string fx = path("fx.toml");
  auto effect = [](const std::string& file) {
    return kHead + "[[emitters]]\ntype = \"file\"\nfile = \"" + file + "\"\n";
  };
  EXPECT_EQ(errors(effect("nope.csv")),
            (std::vector<std::string>{fx + ":7:8: error: emitters.0.file: no such file \"" +
                                      path("nope.csv") + "\" " + expectedFile()}));
  std::ofstream(path("pts.txt")) << "1 2 3\n";
  EXPECT_EQ(errors(effect("pts.txt")),
            (std::vector<std::string>{fx + ":7:8: error: emitters.0.file: \"" + path("pts.txt") +
                                      "\" is neither a .vdb nor a .csv file " + expectedFile()}));
  fs::create_directories(path("dir.vdb"));
  EXPECT_EQ(errors(effect("dir.vdb")),
            (std::vector<std::string>{fx + ":7:8: error: emitters.0.file: \"" + path("dir.vdb") +
                                      "\" is a directory " + expectedFile()}));
  // An empty cache: a header and no rows.
  io::writeCsvCache(io::FrameData{}, path("empty.csv"));
  EXPECT_EQ(errors(effect("empty.csv")),
            (std::vector<std::string>{fx + ":7:8: error: emitters.0.file: \"" + path("empty.csv") +
                                      "\" holds no points " + expectedFile(", not empty")}));
  // Unreadable: not a cache, and a VDB file cut short.
  std::ofstream(path("junk.csv")) << "x,y,z\n1,2,3\n";
  EXPECT_EQ(errors(effect("junk.csv")),
            (std::vector<std::string>{fx + ":7:8: error: emitters.0.file: \"" + path("junk.csv") +
                                      "\" cannot be read: " + path("junk.csv") +
                                      ":1: not a tickfx CSV cache header " + expectedFile()}));
  io::writeVdbPointCache(points(), io::VdbCacheMetadata{}, path("full.vdb"));
  const std::string bytes = test::fileBytes(path("full.vdb"));
  std::ofstream(path("cut.vdb"), std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  EXPECT_EQ(errors(effect("cut.vdb")),
            (std::vector<std::string>{
                fx + ":7:8: error: emitters.0.file: \"" + path("cut.vdb") +
                "\" cannot be read: " + path("cut.vdb") +
                ": grid 'points': cannot read the grid (the file is truncated: a grid ends at "
                "byte " +
                std::to_string(bytes.size()) + " of " + std::to_string(bytes.size() / 2) + ") " +
                expectedFile()}));
  // Points the simulation cannot take: beyond 1e9 m (or inf, nan), or as fast.
  io::FrameData far = points();
  far.position.y[2] = 1e30f;
  io::writeCsvCache(far, path("far.csv"));
  EXPECT_EQ(errors(effect("far.csv")),
            (std::vector<std::string>{fx + ":7:8: error: emitters.0.file: \"" + path("far.csv") +
                                      "\": the point of id 16 is at [0.74, 1e+30, -1.46] "
                                      "(expected points and velocities with every coordinate "
                                      "from -1e9 to 1e9)"}));
  far = points();
  far.velocity.z[0] = -std::numeric_limits<float>::infinity();
  io::writeCsvCache(far, path("fast.csv"));
  EXPECT_EQ(errors(effect("fast.csv")),
            (std::vector<std::string>{fx + ":7:8: error: emitters.0.file: \"" + path("fast.csv") +
                                      "\": the point of id 10 has the velocity [0, 1, -inf] "
                                      "(expected points and velocities with every coordinate "
                                      "from -1e9 to 1e9)"}));
  // An override names the file the same way, relative to the effect file.
  io::writeCsvCache(points(), path("pts.csv"));
  EXPECT_EQ(errors(effect("pts.csv"), {"emitters.0.file=other.csv"}),
            (std::vector<std::string>{"--set emitters.0.file: error: emitters.0.file: no such "
                                      "file \"" +
                                      path("other.csv") + "\" " + expectedFile()}));
}

TEST_F(ioFileEmitter, KeysThatDoNotApplyAndAMissingFile) {
  io::writeCsvCache(points(), path("pts.csv"));
  const std::string fx = path("fx.toml");
  const std::string fileKeys =
      "(expected for a file emitter: type, name, file, position, rate, start, stop, bursts, "
      "direction, speed, speed_jitter, spread, lifetime, lifetime_jitter, mass, attributes)";
  EXPECT_EQ(errors(kHead + R"([[emitters]]
type = "file"
fiel = "pts.csv"
shape = "sphere"
stiffness = 3
[[emitters]]
file = "pts.csv"
rate = 1
)"),
            (std::vector<std::string>{
                fx + ":5:1: error: emitters.0.file: missing " + expectedFile(),
                fx + ":7:1: error: emitters.0.fiel: unknown key \"fiel\" (did you mean \"file\"?)",
                fx +
                    ":8:1: error: emitters.0.shape: does not apply to an emitter of type "
                    "\"file\" " +
                    fileKeys,
                fx +
                    ":9:1: error: emitters.0.stiffness: does not apply to an emitter of type "
                    "\"file\" " +
                    fileKeys,
                fx + ":11:1: error: emitters.1.file: does not apply to an emitter of type "
                     "\"particles\" (expected type = \"file\" for file)"}));
  // A CSV cache gives every point its velocity: the emitter's velocity keys would be ignored.
  EXPECT_EQ(errors(kHead + R"([[emitters]]
type = "file"
file = "pts.csv"
speed = 2.0
spread = 10.0
)"),
            (std::vector<std::string>{
                fx + ":8:9: error: emitters.0.speed: does not apply: \"" + path("pts.csv") +
                    "\" gives every point its velocity (expected direction, speed, speed_jitter "
                    "and spread only with a .vdb file without v)",
                fx + ":9:10: error: emitters.0.spread: does not apply: \"" + path("pts.csv") +
                    "\" gives every point its velocity (expected direction, speed, speed_jitter "
                    "and spread only with a .vdb file without v)"}));
  // The burst of every point may not exceed max_particles; a rate may.
  const std::string small =
      "format_version = 1\n[simulation]\nstep_rate = 10\nmax_particles = 5\n[[emitters]]\n"
      "type = \"file\"\nfile = \"pts.csv\"\n";
  EXPECT_EQ(errors(small),
            (std::vector<std::string>{
                fx + ":7:8: error: emitters.0.file: 7 points are more than "
                     "simulation.max_particles = 5 (expected at most max_particles points for the "
                     "burst of every point, or a rate or bursts)"}));
  EXPECT_TRUE(errors(small + "rate = 100\n").empty());
}

}  // namespace
}  // namespace tickfx
