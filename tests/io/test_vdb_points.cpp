// VDB point caches (io/cache/VdbPointCache): a frame read back through OpenVDB itself has every
// attribute's bits and the run's metadata; broken files fail with the file and grid named.
// Every file is written into a temporary directory of the test and removed afterwards.
#include <gtest/gtest.h>
#include <unistd.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "FlippedBitTestSupport.h"
#include "PointCacheTestSupport.h"
#include "VdbTestData.h"
#include "io/cache/FrameData.h"
#include "io/cache/VdbPointCache.h"
#include "tests/support/FileBytes.h"

namespace tickfx::io {
namespace {

namespace fs = std::filesystem;
namespace vdbt = tickfx::vdb_test;
using test::fileBytes;

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kDenormal = std::numeric_limits<float>::denorm_min();

std::uint32_t bits(float x) { return std::bit_cast<std::uint32_t>(x); }

class ioVdbPoints : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("tickfx_vdb_points_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path path(const std::string& name) const { return dir_ / name; }

  fs::path dir_;
};

VdbCacheMetadata sampleMetadata() {
  return VdbCacheMetadata{"0123456789abcdef", 9223372036854775807ull, 240, "velocity_verlet",
                          "0.1.0"};
}

// Particles at odd places with odd values: zero and −0.0, denormals, halves (on voxel faces),
// coordinates past the 2³⁰ bound and up to 1e30 and inf, ids past 2⁵³ and past 2⁶³, and two
// custom attributes. Rows in id order, as FrameData promises.
FrameData oddFrame() {
  const std::vector<std::array<float, 3>> positions = {
      {0.0f, -0.0f, kDenormal},
      {-kDenormal, 0.5f, -0.5f},
      {1.5f, -2.5f, 3.25f},
      {0.49999997f, -0.49999997f, 7.999999f},
      {123456.79f, -98765.43f, 16777217.0f},
      {1e30f, -1e30f, 3e9f},
      {1073741824.0f, -1073741824.0f, 1073741760.0f},
      {kInf, -kInf, 1e-30f},
      {std::numeric_limits<float>::min(), -std::numeric_limits<float>::max(), 0.1f},
      {-7.75f, 8.125f, -1e-7f},
  };
  const std::vector<std::uint64_t> ids = {
      0,    1, 2, 17, 4096, (1ull << 53) + 1, (1ull << 60) + 3, (1ull << 62) + 7, (1ull << 63) + 5,
      ~0ull};
  FrameData f;
  f.frame = 42;
  f.timeSeconds = 1.75;
  const auto n = static_cast<Eigen::Index>(positions.size());
  f.id.assign(ids.begin(), ids.end());
  f.position.resize(n);
  f.velocity.resize(n);
  f.age.resize(n);
  f.life.resize(n);
  f.mass.resize(n);
  f.attributeNames = {"heat", "Cd_r"};
  f.attributes.assign(2, FloatColumn::Zero(n));
  const float odd[] = {0.0f,    -0.0f, kDenormal, -kDenormal, 1e30f,
                       -1e-30f, kInf,  0.1f,      3.0f,       2e-45f};
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    for (int c = 0; c < 3; ++c) {
      f.position[c][i] = positions[k][static_cast<std::size_t>(c)];
      f.velocity[c][i] = odd[(k + static_cast<std::size_t>(c)) % 10];
    }
    f.age[i] = odd[(k + 3) % 10];
    f.life[i] = i % 2 == 0 ? kInf : odd[(k + 4) % 10];
    f.mass[i] = odd[(k + 5) % 10];
    f.attributes[0][i] = odd[(k + 6) % 10];
    f.attributes[1][i] = -odd[(k + 7) % 10];
  }
  return f;
}

// Bitwise equality of every column; `signOfZero` false lets a −0.0 position read as +0.0.
void expectSameBits(const FrameData& got, const FrameData& want, bool signOfZero = true) {
  ASSERT_EQ(got.size(), want.size());
  EXPECT_EQ(got.id, want.id);
  for (Eigen::Index i = 0; i < static_cast<Eigen::Index>(want.size()); ++i) {
    for (int c = 0; c < 3; ++c) {
      const float p = want.position[c][i];
      const float expected = !signOfZero && p == 0.0f ? 0.0f : p;
      EXPECT_EQ(bits(got.position[c][i]), bits(expected)) << "row " << i << " P" << c << " " << p;
      EXPECT_EQ(bits(got.velocity[c][i]), bits(want.velocity[c][i])) << "row " << i;
    }
    EXPECT_EQ(bits(got.age[i]), bits(want.age[i])) << "row " << i;
    EXPECT_EQ(bits(got.life[i]), bits(want.life[i])) << "row " << i;
    EXPECT_EQ(bits(got.mass[i]), bits(want.mass[i])) << "row " << i;
  }
  ASSERT_EQ(got.attributeNames, want.attributeNames);
  for (std::size_t a = 0; a < want.attributes.size(); ++a) {
    for (Eigen::Index i = 0; i < static_cast<Eigen::Index>(want.size()); ++i)
      EXPECT_EQ(bits(got.attributes[a][i]), bits(want.attributes[a][i])) << want.attributeNames[a];
  }
}

// n rows, ids 1, 4, 7, ... (increasing with gaps), age 0, immortal, 1 kg; P and v per row and
// component from `position(i, c)` and `velocity(i, c)`.
template <typename Position, typename Velocity>
FrameData rowsOf(Eigen::Index n, Position position, Velocity velocity) {
  FrameData frame;
  frame.position.resize(n);
  frame.velocity.resize(n);
  frame.age = FloatColumn::Zero(n);
  frame.life = FloatColumn::Constant(n, kInf);
  frame.mass = FloatColumn::Ones(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    frame.id.push_back(static_cast<std::uint64_t>(3 * i + 1));
    for (int c = 0; c < 3; ++c) {
      frame.position[c][i] = position(i, c);
      frame.velocity[c][i] = velocity(i, c);
    }
  }
  return frame;
}

// A low-discrepancy value in [0, 1) for row i, component c: points scattered over a box.
double scattered(Eigen::Index i, int c) {
  return std::fmod(0.5 + (0.7548776662466927 + 0.21 * c) * static_cast<double>(i + 1), 1.0);
}

// ---- the cache read back through OpenVDB ------------------------------------------------------

TEST_F(ioVdbPoints, OpenVdbReadsEveryAttributeBitwiseAndTheMetadata) {
  const FrameData frame = oddFrame();
  writeVdbPointCache(frame, sampleMetadata(), path("f.vdb"));

  const vdbt::PointsGridRead grid = vdbt::readPointsGrid(path("f.vdb"), "points");
  // The metadata a pipeline reads.
  EXPECT_EQ(grid.stringMetadata.at("tickfx_effect_hash"), "0123456789abcdef");
  EXPECT_EQ(grid.int64Metadata.at("tickfx_seed"), 9223372036854775807);
  EXPECT_EQ(grid.int64Metadata.at("tickfx_step_rate"), 240);
  EXPECT_EQ(grid.stringMetadata.at("tickfx_integrator"), "velocity_verlet");
  EXPECT_EQ(grid.int64Metadata.at("tickfx_frame"), 42);
  EXPECT_EQ(grid.doubleMetadata.at("tickfx_time"), 1.75);
  EXPECT_EQ(grid.stringMetadata.at("tickfx_version"), "0.1.0");
  EXPECT_EQ(grid.int64Metadata.at("tickfx_point_count"), 10);
  EXPECT_EQ(grid.voxelSize, (std::array<double, 3>{1.0, 1.0, 1.0}));
  EXPECT_EQ(grid.pointCount, 10u);

  // Each point as OpenVDB gives it: world position (voxel + P) · transform, and the attributes,
  // by id.
  std::vector<std::string> names;
  for (const std::vector<vdbt::PointAttributeInfo>& leaf : grid.leaves) {
    names.clear();
    std::map<std::string, std::string> types = vdbt::attributeTypes(leaf);
    for (const vdbt::PointAttributeInfo& a : leaf) {
      names.push_back(a.name);
      if (a.name == "P") {
        EXPECT_EQ(a.codec, "null");
      }
    }
    EXPECT_EQ(types["P"], "vec3s");
    EXPECT_EQ(types["v"], "vec3s");
    EXPECT_EQ(types["id"], "int64");
    for (const char* name : {"age", "life", "mass", "heat", "Cd_r"})
      EXPECT_EQ(types[name], "float") << name;
  }
  std::map<std::uint64_t, std::vector<std::uint32_t>> seen;
  for (const vdbt::PointRead& point : grid.points) {
    std::vector<std::uint32_t> values;
    for (int c = 0; c < 3; ++c) values.push_back(bits(point.world[c]));
    for (int c = 0; c < 3; ++c) values.push_back(bits(point.floats.at("v").at(c)));
    for (const char* name : {"age", "life", "mass", "heat", "Cd_r"})
      values.push_back(bits(point.floats.at(name).at(0)));
    const auto key = static_cast<std::uint64_t>(point.int64s.at("id"));
    EXPECT_EQ(seen.count(key), 0u);
    seen[key] = values;
    // Points within the bound sit in their nearest voxel, as OpenVDB's convention has it.
    for (int c = 0; c < 3; ++c) {
      if (point.voxel[c] != 0) {
        EXPECT_LE(std::abs(point.offset[c]), 0.5f);
      }
    }
  }
  EXPECT_EQ(names,
            (std::vector<std::string>{"P", "v", "id", "age", "life", "mass", "heat", "Cd_r"}));
  ASSERT_EQ(seen.size(), frame.size());
  for (std::size_t k = 0; k < frame.size(); ++k) {
    const auto i = static_cast<Eigen::Index>(k);
    ASSERT_EQ(seen.count(frame.id[k]), 1u) << frame.id[k];
    const std::vector<std::uint32_t>& got = seen[frame.id[k]];
    std::vector<std::uint32_t> want;
    // (voxel + P) · 1 is exact, but a sum cannot give −0.0: OpenVDB's reading shows it as +0.0.
    for (int c = 0; c < 3; ++c) want.push_back(bits(frame.position[c][i] + 0.0f));
    for (int c = 0; c < 3; ++c) want.push_back(bits(frame.velocity[c][i]));
    for (const FloatColumn* col :
         {&frame.age, &frame.life, &frame.mass, &frame.attributes[0], &frame.attributes[1]})
      want.push_back(bits((*col)[i]));
    EXPECT_EQ(got, want) << "id " << frame.id[k];
  }
  // Points are spread over voxels (not all kept in one).
  EXPECT_GT(grid.activeVoxelCount, 5u);
}

TEST_F(ioVdbPoints, ReadBackGivesTheFrameInIdOrderWithItsBitsAndMetadata) {
  const FrameData frame = oddFrame();
  writeVdbPointCache(frame, sampleMetadata(), path("f.vdb"));
  VdbCacheContents contents;
  const FrameData back = readVdbPointCache(path("f.vdb"), &contents);
  expectSameBits(back, frame);  // −0.0 included
  EXPECT_EQ(back.frame, 42);
  EXPECT_EQ(back.timeSeconds, 1.75);
  EXPECT_EQ(contents.metadata.effectHash, "0123456789abcdef");
  EXPECT_EQ(contents.metadata.seed, 9223372036854775807ull);
  EXPECT_EQ(contents.metadata.stepRateHz, 240);
  EXPECT_EQ(contents.metadata.integrator, "velocity_verlet");
  EXPECT_EQ(contents.metadata.tickfxVersion, "0.1.0");
  EXPECT_TRUE(contents.hasVelocity && contents.hasId && contents.hasAge && contents.hasLife &&
              contents.hasMass);
}

TEST_F(ioVdbPoints, ManyPointsOverManyLeavesComeBackInIdOrder) {
  // 5000 points scattered over ±200 m (hundreds of leaves), ids increasing with gaps.
  const FrameData frame = rowsOf(
      5000,
      [](Eigen::Index i, int c) { return static_cast<float>(400.0 * scattered(i, c) - 200.0); },
      [](Eigen::Index i, int c) { return static_cast<float>(scattered(i, c)); });
  writeVdbPointCache(frame, sampleMetadata(), path("many.vdb"));
  const FrameData back = readVdbPointCache(path("many.vdb"));
  expectSameBits(back, frame);
  EXPECT_GT(vdbt::readPointsGrid(path("many.vdb"), "points").leaves.size(), 100u);
}

// Blosc is lossless: the odd frame (−0.0, denormals, inf, ids past 2⁶³) reads back bit for bit.
TEST_F(ioVdbPoints, BloscCompressedCachesReadBackBitForBitAndSmaller) {
  const FrameData frame = oddFrame();
  const VdbCacheOptions blosc{VdbCacheOptions::Compression::Blosc};
  writeVdbPointCache(frame, sampleMetadata(), path("b.vdb"), blosc);
  expectSameBits(readVdbPointCache(path("b.vdb")), frame);
  // Ids in steps of 3 and velocities of few distinct values compress: the file is smaller.
  const FrameData smooth = rowsOf(
      5000,
      [](Eigen::Index i, int c) {
        return 0.01f * static_cast<float>(i % 500) + static_cast<float>(c);
      },
      [](Eigen::Index, int c) { return static_cast<float>(c); });
  writeVdbPointCache(smooth, sampleMetadata(), path("s.vdb"), blosc);
  writeVdbPointCache(smooth, sampleMetadata(), path("n.vdb"));
  expectSameBits(readVdbPointCache(path("s.vdb")), smooth);
  EXPECT_LT(2 * fs::file_size(path("s.vdb")), fs::file_size(path("n.vdb")));
}

// Fixed16 stores P as 16 bits within the point's 1 m voxel: within 1/65535 m of the float
// (plus the float's own rounding of voxel + offset), every other column exact.
TEST_F(ioVdbPoints, Fixed16PositionsReadBackWithin1Over65535Metre) {
  const Eigen::Index n = 3000;
  FrameData frame = rowsOf(
      n, [](Eigen::Index i, int c) { return static_cast<float>(120.0 * scattered(i, c) - 60.0); },
      [](Eigen::Index i, int c) { return static_cast<float>(scattered(i, c) - 0.5); });
  // Points on voxel faces and corners of the fixed-point range.
  frame.position[0][0] = 0.5f;
  frame.position[1][0] = -0.5f;
  frame.position[2][0] = 2.4999998f;
  const VdbCacheOptions fixed16{VdbCacheOptions::Compression::None,
                                VdbCacheOptions::Positions::Fixed16};
  writeVdbPointCache(frame, sampleMetadata(), path("q.vdb"), fixed16);
  const FrameData back = readVdbPointCache(path("q.vdb"));
  ASSERT_EQ(back.size(), frame.size());
  EXPECT_EQ(back.id, frame.id);
  double worst = 0.0;
  for (Eigen::Index i = 0; i < n; ++i) {
    for (int c = 0; c < 3; ++c) {
      const double want = frame.position[c][i];
      const double error = std::abs(static_cast<double>(back.position[c][i]) - want);
      const double bound = 1.0 / 65535.0 + std::abs(want) * 0x1p-23;
      EXPECT_LE(error, bound) << "row " << i << " P" << c << " " << want;
      worst = std::max(worst, error);
      EXPECT_EQ(bits(back.velocity[c][i]), bits(frame.velocity[c][i])) << "row " << i;
    }
    EXPECT_EQ(bits(back.age[i]), bits(frame.age[i]));
  }
  // Quantised, not exact: a test of a writer that ignored the option would pass the bound too.
  EXPECT_GT(worst, 1e-6);
  // Smaller: 6 bytes a point instead of 12 for P.
  writeVdbPointCache(frame, sampleMetadata(), path("x.vdb"));
  EXPECT_LT(fs::file_size(path("q.vdb")) + 5 * static_cast<std::uintmax_t>(n),
            fs::file_size(path("x.vdb")));
}

// What fixed point cannot hold: a NaN reads as (about) 0, a coordinate beyond ±2³⁰ m (inf included)
// keeps its sign, half a metre, in voxel 0 of its axis.
TEST_F(ioVdbPoints, Fixed16KeepsOnlyTheSignOfWhatItCannotHold) {
  FrameData frame;
  frame.resize(1, {});
  frame.id = {1};
  frame.position[0][0] = std::numeric_limits<float>::quiet_NaN();
  frame.position[1][0] = -kInf;
  frame.position[2][0] = 3e9f;
  for (int c = 0; c < 3; ++c) frame.velocity[c][0] = 0.0f;
  frame.age[0] = 0.0f;
  frame.life[0] = 1.0f;
  frame.mass[0] = 1.0f;
  writeVdbPointCache(frame, sampleMetadata(), path("far.vdb"),
                     {VdbCacheOptions::Compression::None, VdbCacheOptions::Positions::Fixed16});
  const FrameData back = readVdbPointCache(path("far.vdb"));
  ASSERT_EQ(back.size(), 1u);
  // Fixed point has no 0: the middle code reads 32767/65535 − 0.5.
  EXPECT_EQ(back.position[0][0], 32767.0f / 65535.0f - 0.5f);  // as OpenVDB decodes, in float
  EXPECT_EQ(back.position[1][0], -0.5f);
  EXPECT_EQ(back.position[2][0], 0.5f);
}

TEST_F(ioVdbPoints, AnEmptyFrameIsAnEmptyGrid) {
  FrameData empty;
  empty.frame = 1;
  writeVdbPointCache(empty, sampleMetadata(), path("empty.vdb"));
  const FrameData back = readVdbPointCache(path("empty.vdb"));
  EXPECT_EQ(back.size(), 0u);
  EXPECT_EQ(back.frame, 1);
}

TEST_F(ioVdbPoints, AForeignPointsFileReadsWithDefaultsForWhatItLacks) {
  // Points as another tool writes them: OpenVDB's own conversion, a 0.25 m voxel, P in a 16-bit
  // fixed-point codec, no v, id or age; one extra float attribute, an int32 one (a column of
  // whole numbers), and Houdini's colour Cd (vec3s), which reads as Cd_r, Cd_g and Cd_b.
  vdbt::PointsFileSpec foreign;
  foreign.positions = {{0.1, 0.2, 0.3}, {-1.0, 2.0, 0.5}, {3.0, -3.0, 1.0}};
  foreign.voxelSize = 0.25;
  foreign.codec = vdbt::PositionCodec::FixedPoint16;
  foreign.attributes = {{"density", vdbt::PointAttributeSpec::Type::Float, {2.5f}},
                        {"flags", vdbt::PointAttributeSpec::Type::Int32, {7.0f}},
                        {"Cd", vdbt::PointAttributeSpec::Type::Vec3s, {0.25f, 0.5f, 1.0f}}};
  vdbt::writePointsFile(path("foreign.vdb"), foreign);
  const auto& positions = foreign.positions;

  VdbCacheContents contents;
  const FrameData back = readVdbPointCache(path("foreign.vdb"), &contents);
  ASSERT_EQ(back.size(), 3u);
  EXPECT_FALSE(contents.hasVelocity || contents.hasId || contents.hasAge || contents.hasLife ||
               contents.hasMass);
  EXPECT_EQ(back.attributeNames,
            (std::vector<std::string>{"density", "flags", "Cd_r", "Cd_g", "Cd_b"}));
  // Rows in file order, numbered from 0; positions within the codec's resolution.
  EXPECT_EQ(back.id, (UninitialisedVector<std::uint64_t>{0, 1, 2}));
  std::vector<bool> matched(3, false);
  for (Eigen::Index r = 0; r < 3; ++r) {
    EXPECT_EQ(back.velocity.x[r], 0.0f);
    EXPECT_EQ(back.age[r], 0.0f);
    EXPECT_EQ(back.life[r], kInf);
    EXPECT_EQ(back.mass[r], 1.0f);
    EXPECT_EQ(back.attributes[0][r], 2.5f);
    EXPECT_EQ(back.attributes[1][r], 7.0f);
    EXPECT_EQ(back.attributes[2][r], 0.25f);
    EXPECT_EQ(back.attributes[3][r], 0.5f);
    EXPECT_EQ(back.attributes[4][r], 1.0f);
    for (std::size_t k = 0; k < 3; ++k) {
      const Eigen::Vector3d p(back.position.x[r], back.position.y[r], back.position.z[r]);
      if ((p - Eigen::Vector3d(positions[k][0], positions[k][1], positions[k][2])).norm() < 1e-5)
        matched[k] = true;
    }
  }
  EXPECT_EQ(matched, std::vector<bool>(3, true));
}

TEST_F(ioVdbPoints, PointsFilesInEveryLayoutOpenVdbWritesRead) {
  // Checking every byte before OpenVDB reads it must not refuse a valid file: paged blosc arrays
  // over many leaves, raw arrays (no blosc: no compression, or zip, which points do not use), a
  // strided array, a uniform one, a string attribute and a group.
  using Type = vdbt::PointAttributeSpec::Type;
  vdbt::PointsFileSpec layout;
  for (int i = 0; i < 300; ++i) layout.positions.push_back({0.1 * i, 0.05 * i, -0.07 * i});
  layout.voxelSize = 0.5;
  layout.attributes = {{"density", Type::Float, {2.5f}},
                       {"triple", Type::Float, {1.0f}, /*stride=*/3},
                       {"label", Type::String},
                       {"chosen", Type::Group},
                       {"v", Type::Vec3s, {1.0f, 2.0f, 3.0f}}};
  const auto& positions = layout.positions;
  vdbt::writePointsFile(path("p.vdb"), layout);
  ASSERT_GT(vdbt::readPointsGrid(path("p.vdb"), "points").leaves.size(), 5u);
  for (const vdbt::Compression compression :
       {vdbt::Compression::BloscActiveMask, vdbt::Compression::None, vdbt::Compression::Zip}) {
    SCOPED_TRACE(vdbt::toString(compression));
    layout.compression = compression;
    vdbt::writePointsFile(path("p.vdb"), layout);
    const FrameData back = readVdbPointCache(path("p.vdb"));
    ASSERT_EQ(back.size(), positions.size());
    EXPECT_EQ(back.attributeNames, (std::vector<std::string>{"density", "triple"}));
    for (Eigen::Index r = 0; r < 300; ++r) {
      EXPECT_EQ(back.attributes[0][r], 2.5f);
      EXPECT_EQ(back.attributes[1][r], 1.0f);
      EXPECT_EQ(back.velocity.y[r], 2.0f);
    }
  }
}

// ---- errors ------------------------------------------------------------------------------------

std::string errorOf(const fs::path& file) {
  try {
    readVdbPointCache(file);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "no error";
}

TEST_F(ioVdbPoints, MissingTruncatedAndForeignFilesNameTheFileAndGrid) {
  const std::string missing = path("missing.vdb").string();
  EXPECT_EQ(errorOf(missing), missing + ": grid 'points': no such file");

  const FrameData frame = oddFrame();
  writeVdbPointCache(frame, sampleMetadata(), path("f.vdb"));
  const std::string bytes = fileBytes(path("f.vdb"));
  ASSERT_GT(bytes.size(), 400u);
  // Cut inside the grid data (caught before OpenVDB reads it: OpenVDB 10 may hang there), and
  // inside the header.
  for (const std::size_t size : {bytes.size() - 1, bytes.size() / 2, std::size_t{300}}) {
    const std::string cut = path("cut" + std::to_string(size) + ".vdb").string();
    std::ofstream(cut, std::ios::binary) << bytes.substr(0, size);
    EXPECT_EQ(errorOf(cut), cut +
                                ": grid 'points': cannot read the grid (the file is truncated: a "
                                "grid ends at byte " +
                                std::to_string(bytes.size()) + " of " + std::to_string(size) + ")");
  }
  const std::string empty = path("empty.vdb").string();
  std::ofstream(empty, std::ios::binary).flush();
  EXPECT_EQ(errorOf(empty).rfind(empty + ": grid 'points': cannot open the file as OpenVDB (", 0),
            0u)
      << errorOf(empty);
  const std::string head = path("head.vdb").string();
  std::ofstream(head, std::ios::binary) << bytes.substr(0, 20);
  EXPECT_EQ(errorOf(head), head + ": grid 'points': cannot read the grid (the file is truncated)");

  // A file without the grid, and a "points" grid of another type.
  vdbt::GridFileSpec density;
  density.name = "density";
  density.type = vdbt::GridType::Float;
  density.background = {1.0};
  vdbt::writeGridFile(path("density.vdb"), density);
  EXPECT_EQ(errorOf(path("density.vdb")),
            path("density.vdb").string() + ": grid 'points': no such grid (the file has: density)");
  density.name = "points";
  vdbt::writeGridFile(path("float.vdb"), density);
  EXPECT_EQ(errorOf(path("float.vdb")), path("float.vdb").string() +
                                            ": grid 'points': is a grid of type Tree_float_5_4_3 "
                                            "(expected a PointDataGrid)");
}

TEST_F(ioVdbPoints, EveryFlippedBitReadsOrIsRefusedWithAMessage) {
  // A small cache: 12 points over 4 leaves (so pages span leaves), every attribute, a custom one.
  FrameData frame;
  const Eigen::Index n = 12;
  frame.position.resize(n);
  frame.velocity.resize(n);
  frame.age = FloatColumn::Constant(n, 0.5f);
  frame.life = FloatColumn::Constant(n, 5.0f);
  frame.mass = FloatColumn::Ones(n);
  frame.attributeNames = {"heat"};
  frame.attributes.assign(1, FloatColumn::Zero(n));
  for (Eigen::Index i = 0; i < n; ++i) {
    frame.id.push_back(static_cast<std::uint64_t>(3 * i + 1));
    for (int c = 0; c < 3; ++c) {
      frame.position[c][i] = 0.75f * static_cast<float>(i) + static_cast<float>(c);
      frame.velocity[c][i] = 0.5f * static_cast<float>(c - i);
    }
    frame.attributes[0][i] = static_cast<float>(i);
  }
  // Every layout a cache can have: arrays whole, in blosc pages, positions in fixed point.
  using Options = VdbCacheOptions;
  const std::pair<const char*, Options> layouts[] = {
      {"the default", Options{}},
      {"blosc", Options{Options::Compression::Blosc, Options::Positions::Exact}},
      {"fixed16", Options{Options::Compression::None, Options::Positions::Fixed16}}};
  for (const auto& layout : layouts) {
    // (A copy, not a structured binding: clang 14 cannot capture those in the lambda below.)
    const std::string label = layout.first;
    const Options& options = layout.second;
    writeVdbPointCache(frame, sampleMetadata(), path("f.vdb"), options);
    const std::string bytes = fileBytes(path("f.vdb"));
    ASSERT_GT(bytes.size(), 10000u);  // the root's child alone has two 4 KB masks

    // Bit i mod 8 of byte i flipped, each its own file. OpenVDB 10 trusts the sizes, counts and
    // flags it reads: on hundreds of these files it aborted on an assertion (its paged streams,
    // blosc pages), crashed, or allocated gigabytes. Each now reads, or is refused naming the file.
    const test::FlippedBits flips = test::loadEveryFlippedBit(
        bytes, [&](std::size_t i) { return path("flip" + std::to_string(i) + ".vdb").string(); },
        "points",
        [&](const std::string& file, std::size_t i) {
          const FrameData back = readVdbPointCache(file);
          // What was read is a frame of the cache's size, whatever values the flip changed.
          EXPECT_EQ(back.size(), frame.size()) << "byte " << i << " of " << label;
        });
    const std::size_t read = flips.loaded, refused = flips.refusals.size();
    std::size_t corrupt = 0;
    for (const std::string& what : flips.refusals) {
      if (what.find("the file is corrupt at byte ") != std::string::npos) ++corrupt;
    }
    EXPECT_EQ(read + refused, bytes.size()) << label;
    // Values (positions, velocities, metadata values, unused bits) still read; most of the bytes
    // are structure, and most refusals name the byte where the file stops making sense.
    EXPECT_GT(read, 300u) << label;
    EXPECT_GT(refused, bytes.size() / 2) << label;
    EXPECT_GT(corrupt, refused / 2) << label;
  }

  // The first attribute array's byte count (a uint64, 6 + 12 bytes for one point's P) one too
  // many: OpenVDB's paged stream asserted (mByteIndex <= mUncompressedBytes).
  writeVdbPointCache(test::onePointFrame(), sampleMetadata(), path("one.vdb"), test::kPagedArrays);
  const std::size_t at = test::overstateFirstAttributeArray(path("one.vdb"));
  ASSERT_NE(at, std::string::npos);
  EXPECT_EQ(errorOf(path("one.vdb")), path("one.vdb").string() +
                                          ": grid 'points': cannot read the grid (the file is "
                                          "corrupt at byte " +
                                          std::to_string(at) +
                                          ": an attribute array of 13 bytes where 12 are "
                                          "expected)");
}

// OpenVDB makes a point tree's leaves with its background as their value and asserts that it is
// zero: a file with another background is refused at that byte, before OpenVDB reads it. The
// background is the only run of bytes early in the file whose change gives that refusal.
TEST_F(ioVdbPoints, APointTreeWhoseBackgroundIsNotZeroIsRefused) {
  writeVdbPointCache(test::onePointFrame(), sampleMetadata(), path("one.vdb"));
  const std::string bytes = fileBytes(path("one.vdb"));
  const std::string file = path("changed.vdb").string();
  std::vector<std::size_t> refusedAt;
  std::string first;
  for (std::size_t i = 0; i < std::min<std::size_t>(bytes.size(), 2000); ++i) {
    std::string changed = bytes;
    changed[i] = static_cast<char>(changed[i] ^ 0x40);
    std::ofstream(file, std::ios::binary) << changed;
    const std::string error = errorOf(file);
    if (error.find("background is not zero") == std::string::npos) continue;
    if (refusedAt.empty()) first = error;
    refusedAt.push_back(i);
  }
  ASSERT_EQ(refusedAt.size(), 4u);  // a PointIndex32's four bytes
  EXPECT_EQ(refusedAt.back() - refusedAt.front(), 3u);
  EXPECT_EQ(first, file + ": grid 'points': cannot read the grid (the file is corrupt at byte " +
                       std::to_string(refusedAt.front()) +
                       ": a point data tree whose background is not zero)");
}

TEST_F(ioVdbPoints, AFailedWriteLeavesNoFile) {
  FrameData frame = oddFrame();
  // Into a directory that does not exist: the error names the file, nothing is left behind.
  const fs::path nowhere = path("no/such/dir/f.vdb");
  try {
    writeVdbPointCache(frame, sampleMetadata(), nowhere);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()),
              nowhere.string() + ": error: cannot write (No such file or directory)");
  }
  EXPECT_FALSE(fs::exists(path("no")));
  // A custom attribute named like a standard one, or not a name OpenVDB takes: refused before
  // anything is written; an existing file is left as it was.
  writeVdbPointCache(frame, sampleMetadata(), path("f.vdb"));
  const auto size = fs::file_size(path("f.vdb"));
  frame.attributeNames[0] = "mass";
  EXPECT_THROW(writeVdbPointCache(frame, sampleMetadata(), path("f.vdb")), std::invalid_argument);
  frame.attributeNames[0] = "hot spot";
  EXPECT_THROW(writeVdbPointCache(frame, sampleMetadata(), path("f.vdb")), std::invalid_argument);
  EXPECT_EQ(fs::file_size(path("f.vdb")), size);
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 1);
}

}  // namespace
}  // namespace tickfx::io
