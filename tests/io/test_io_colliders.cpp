// [[colliders]] in effect files: every key read, every bad value located with its exact message,
// level sets built from a file, a mesh and a bake, and the build's named errors.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <string>
#include <vector>

#include "VdbTestData.h"
#include "fields/ColliderSet.h"
#include "io/cache/CsvCache.h"
#include "io/cache/FrameData.h"
#include "io/cache/PlyCache.h"
#include "io/cache/VdbPointCache.h"
#include "io/effect/EffectBuilder.h"
#include "io/effect/EffectLint.h"
#include "io/effect/EffectParser.h"
#include "io/mesh/MeshFile.h"
#include "tests/support/FileBytes.h"

namespace tickfx::io {
namespace {

using Lines = std::vector<std::string>;

const char kHead[] = R"(format_version = 1
[simulation]
step_rate = 60
[[emitters]]
rate = 10
)";

std::vector<std::string> messages(const std::string& colliders,
                                  const std::string& file = "bad.toml") {
  const LoadResult result = parseEffect(std::string(kHead) + colliders, file, {});
  std::vector<std::string> out;
  for (const Diagnostic& d : result.diagnostics) out.push_back(d.format());
  return out;
}

EffectSettings parsed(const std::string& colliders, const std::string& file = "fx.toml") {
  const LoadResult result = parseEffect(std::string(kHead) + colliders, file, {});
  EXPECT_TRUE(result.ok()) << (result.diagnostics.empty() ? "" : result.diagnostics[0].format());
  return result.ok() ? *result.effect : EffectSettings{};
}

TEST(ioColliders, EveryKeyIsRead) {
  const EffectSettings e = parsed(R"([[colliders]]
type = "box"
center = [1.0, 2.0, 3.0]
size = [0.5, 0.25, 2.0]
rotation = [10.0, 20.0, 30.0]
radius = 0.01
side = "inside"
response = "slide"
restitution = 0.25
friction = 0.5
spin = { axis = [0.0, 0.0, 2.0], center = [1.0, 0.0, 0.0], rate = 3.0 }
keys = [{ time = 0.0, translate = [0.0, 0.0, 0.0] }, { time = 1.5, translate = [1.0, 0.0, 0.0] }]
[[colliders]]
type = "sphere"
radius = 2.0
particle_radius = 0.1
velocity = [1.0, 0.0, 0.0]
response = "kill"
hits = true
)");
  ASSERT_EQ(e.colliders.size(), 2u);
  const ColliderSettings& b = e.colliders[0];
  EXPECT_EQ(b.type, ColliderType::Box);
  EXPECT_EQ(b.center, Eigen::Vector3d(1.0, 2.0, 3.0));
  EXPECT_EQ(b.size, Eigen::Vector3d(0.5, 0.25, 2.0));
  EXPECT_EQ(b.rotation, Eigen::Vector3d(10.0, 20.0, 30.0));
  EXPECT_EQ(b.particleRadius, 0.01);
  EXPECT_EQ(b.side, ColliderSide::Inside);
  EXPECT_EQ(b.response, ColliderResponse::Slide);
  EXPECT_EQ(b.restitution, 0.25);
  EXPECT_EQ(b.friction, 0.5);
  EXPECT_EQ(b.motion.spinAxis, Eigen::Vector3d(0.0, 0.0, 2.0));
  EXPECT_EQ(b.motion.spinCenter, Eigen::Vector3d(1.0, 0.0, 0.0));
  EXPECT_EQ(b.motion.spinRate, 3.0);
  ASSERT_EQ(b.motion.keys.size(), 2u);
  EXPECT_EQ(b.motion.keys[1].time, 1.5);
  EXPECT_EQ(b.motion.keys[1].translate, Eigen::Vector3d(1.0, 0.0, 0.0));
  const ColliderSettings& s = e.colliders[1];
  EXPECT_EQ(s.type, ColliderType::Sphere);
  EXPECT_EQ(s.radius, 2.0);
  EXPECT_EQ(s.particleRadius, 0.1);
  EXPECT_EQ(s.motion.velocity, Eigen::Vector3d(1.0, 0.0, 0.0));
  EXPECT_EQ(s.response, ColliderResponse::Kill);
  EXPECT_TRUE(s.recordHits);
  EXPECT_FALSE(b.recordHits);
  // The system has them, in order.
  const auto system = buildSystem(e);
  ASSERT_NE(system->colliders(), nullptr);
  EXPECT_EQ(system->colliders()->size(), 2u);
}

TEST(ioColliders, BadValuesAreLocatedWithTheirMessages) {
  EXPECT_EQ(
      messages(R"([[colliders]]
type = "plain"
[[colliders]]
type = "plane"
restitution = 1.5
frction = 0.2
[[colliders]]
type = "sphere"
center = [0.0, 0.0, 0.0]
[[colliders]]
type = "plane"
size = [1.0, 1.0, 1.0]
response = "bounc"
[[colliders]]
type = "box"
side = "inside"
size = [1.0, 0.02, 1.0]
radius = 0.01
)"),
      (Lines{"bad.toml:7:8: error: colliders.0.type: unknown collider type \"plain\" (did you "
             "mean \"plane\"?)",
             "bad.toml:10:15: error: colliders.1.restitution: 1.5 is out of range (expected a "
             "number from 0 to 1)",
             "bad.toml:11:1: error: colliders.1.frction: unknown key \"frction\" (did you mean "
             "\"friction\"?)",
             "bad.toml:12:1: error: colliders.2.radius: missing (expected metres, a number > 0 "
             "and <= 1e9)",
             "bad.toml:17:1: error: colliders.3.size: does not apply to a collider of type "
             "\"plane\" (expected for plane: type, point, normal, radius, side, response, "
             "restitution, friction, velocity, spin, keys, particle_radius, hits)",
             "bad.toml:18:12: error: colliders.3.response: unknown collision response \"bounc\" "
             "(did you mean \"bounce\"?)",
             "bad.toml:22:14: error: colliders.4.size.1: is no wider than a particle (radius "
             "0.01) (expected a container wider than a particle)"}));
  // The particles' radius has two names on a plane or a box: one of them.
  EXPECT_EQ(messages("[[colliders]]\ntype = \"plane\"\nradius = 0.1\nparticle_radius = 0.1\n"),
            (Lines{"bad.toml:9:19: error: colliders.0.particle_radius: is given with radius, its "
                   "other name (expected one of them)"}));
}

TEST(ioColliders, MotionErrors) {
  EXPECT_EQ(
      messages(R"([[colliders]]
type = "plane"
velocity = [1.0, 0.0, 0.0]
keys = [{ time = 0.0 }]
[[colliders]]
type = "plane"
keys = [{ time = 1.0 }, { time = 0.5, translate = [1.0, 0.0, 0.0] }]
[[colliders]]
type = "plane"
spin = { axis = [0.0, 0.0, 0.0], rat = 1.0 }
)"),
      (Lines{"bad.toml:9:8: error: colliders.0.keys: is given with a velocity (expected either "
             "velocity or keys)",
             "bad.toml:12:34: error: colliders.1.keys.1.time: is not after the key before it "
             "(1) (expected key times strictly increasing)",
             "bad.toml:15:8: error: colliders.2.spin.rate: missing (expected rad/s, a number "
             "from -1e9 to 1e9)",
             "bad.toml:15:17: error: colliders.2.spin.axis: got [0, 0, 0] (expected a "
             "direction [x, y, z], each from -1e9 to 1e9, not all zero)",
             "bad.toml:15:34: error: colliders.2.spin.rat: unknown key \"rat\" (did you mean "
             "\"rate\"?)"}));
}

TEST(ioColliders, LevelSetSources) {
  EXPECT_EQ(
      messages(R"([[colliders]]
type = "level_set"
[[colliders]]
type = "level_set"
file = "a.vdb"
mesh = "a.obj"
[[colliders]]
type = "level_set"
mesh = "a.obj"
[[colliders]]
type = "level_set"
bake = { shape = "cube", voxel_size = 0.1 }
[[colliders]]
type = "level_set"
bake = { shape = "torus", major_radius = 0.5, minor_radius = 1.0, voxel_size = 0.1, radius = 1.0 }
[[colliders]]
type = "level_set"
file = "a.vdb"
voxel_size = 0.1
)"),
      (Lines{"bad.toml:6:1: error: colliders.0.file: missing (expected one of file (a .vdb "
             "level set), mesh (an OBJ or PLY file) or bake)",
             "bad.toml:11:8: error: colliders.1.mesh: is given with file (expected one of "
             "file, mesh and bake)",
             "bad.toml:12:1: error: colliders.2.voxel_size: missing (expected metres, a "
             "number > 0 and <= 1e9)",
             "bad.toml:17:18: error: colliders.3.bake.shape: unknown baked shape \"cube\" "
             "(expected one of: sphere, box, torus)",
             "bad.toml:20:85: error: colliders.4.bake.radius: does not apply to a baked torus "
             "(expected for a torus: shape, center, voxel_size, major_radius, minor_radius)",
             "bad.toml:24:14: error: colliders.5.voxel_size: applies to a level set from mesh "
             "only (expected no voxel_size)"}));
}

class ioCollidersOnDisk : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("tickfx_io_colliders_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string write(const std::string& name, const std::string& bytes) {
    std::ofstream(dir_ / name, std::ios::binary) << bytes;
    return (dir_ / name).string();
  }
  // The build's error for an effect whose one collider is `collider`, or "" when it builds.
  std::string buildError(const std::string& collider) {
    const std::string file = (dir_ / "fx.toml").string();
    const LoadResult r = parseEffect(std::string(kHead) + collider, file, {});
    if (!r.ok()) return "parse: " + r.diagnostics[0].format();
    try {
      buildSystem(*r.effect);
    } catch (const BuildError& e) {
      std::string what = e.what();
      const std::string prefix = dir_.string() + "/";
      for (std::size_t at; (at = what.find(prefix)) != std::string::npos;)
        what.erase(at, prefix.size());
      return what;
    }
    return "";
  }
  std::filesystem::path dir_;
};

// An octahedron: 6 vertices, 8 triangles, closed.
const char kOctahedron[] = R"(# a closed mesh
v 1 0 0
v -1 0 0
v 0 1 0
v 0 -1 0
v 0 0 1
v 0 0 -1
f 1 3 5
f 3 2 5
f 2 4 5
f 4 1 5
f 3 1 6
f 2 3 6
f 4 2 6
f 1 4 6
)";

TEST_F(ioCollidersOnDisk, MeshFilesAreReadOrRefusedByName) {
  write("octahedron.obj", kOctahedron);
  EXPECT_EQ(
      buildError(
          "[[colliders]]\ntype = \"level_set\"\nmesh = \"octahedron.obj\"\nvoxel_size = 0.1\n"),
      "");
  std::string open = kOctahedron;
  open.resize(open.rfind("f 1 4 6"));
  write("open.obj", open);
  const auto withMesh = [](const std::string& file) {
    return "[[colliders]]\ntype = \"level_set\"\nmesh = \"" + file + "\"\nvoxel_size = 0.1\n";
  };
  EXPECT_EQ(buildError(withMesh("open.obj")),
            "fx.toml:8:8: error: colliders.0.mesh: open.obj: is not closed: the edge between "
            "vertices 0 and 3 belongs to 1 triangle (expected 2)");
  write("empty.obj", "");
  EXPECT_EQ(buildError(withMesh("empty.obj")),
            "fx.toml:8:8: error: colliders.0.mesh: empty.obj: is empty (expected an OBJ or PLY "
            "triangle mesh)");
  EXPECT_EQ(buildError(withMesh("missing.ply")),
            "fx.toml:8:8: error: colliders.0.mesh: missing.ply: no such file (expected an OBJ or "
            "PLY triangle mesh)");
  write("bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n");
  EXPECT_EQ(buildError(withMesh("bad.obj")),
            "fx.toml:8:8: error: colliders.0.mesh: bad.obj: line 4: \"4\" is not a vertex "
            "(expected 1 to 3, or -1 to -3)");
  write("cut.ply",
        "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
        "property float y\nproperty float z\nend_header\n\x01\x02");
  EXPECT_EQ(buildError(withMesh("cut.ply")),
            "fx.toml:8:8: error: colliders.0.mesh: cut.ply: is truncated (the data ends at byte "
            "117)");
}

TEST_F(ioCollidersOnDisk, VdbFilesMustHoldAFloatGrid) {
  vdb_test::GridFileSpec sdf;
  sdf.name = "surface";
  sdf.type = vdb_test::GridType::Float;
  sdf.background = {0.3, 0.0, 0.0};
  sdf.activeVoxels = {{{0, 0, 0}, {-0.1, 0.0, 0.0}}};
  vdb_test::GridFileSpec vel;
  vel.name = "vel";
  vel.type = vdb_test::GridType::Vec3s;
  vel.activeVoxels = {{{0, 0, 0}, {1.0, 1.0, 1.0}}};
  vdb_test::writeGridsFile(dir_ / "grids.vdb", {sdf, vel});
  EXPECT_EQ(buildError("[[colliders]]\ntype = \"level_set\"\nfile = \"grids.vdb\"\n"), "");
  EXPECT_EQ(
      buildError("[[colliders]]\ntype = \"level_set\"\nfile = \"grids.vdb\"\ngrid = \"vel\"\n"),
      "fx.toml:8:8: error: colliders.0.file: grids.vdb: grid 'vel': holds vec3s values "
      "(Tree_vec3s_5_4_3); a level set needs float");
  EXPECT_EQ(buildError("[[colliders]]\ntype = \"level_set\"\nfile = \"nothing.vdb\"\n"),
            "fx.toml:8:8: error: colliders.0.file: nothing.vdb: grid 'surface': no such file");
  write("garbage.vdb", std::string("\x20\x42\x44\x56\x00\x00\x00\x00", 8));
  EXPECT_EQ(buildError("[[colliders]]\ntype = \"level_set\"\nfile = \"garbage.vdb\"\n"),
            "fx.toml:8:8: error: colliders.0.file: garbage.vdb: grid 'surface': cannot read the "
            "grid (the file is truncated)");
  std::string bytes = test::fileBytes(dir_ / "grids.vdb");
  write("truncated.vdb", bytes.substr(0, bytes.size() / 2));
  // Where the grid ends depends on OpenVDB's layout; that it is past the file's end does not.
  const std::string cut =
      buildError("[[colliders]]\ntype = \"level_set\"\nfile = \"truncated.vdb\"\n");
  const std::string head =
      "fx.toml:8:8: error: colliders.0.file: truncated.vdb: grid 'surface': cannot read the grid "
      "(the file is truncated: a grid ends at byte ";
  const std::string tail = " of " + std::to_string(bytes.size() / 2) + ")";
  EXPECT_EQ(cut.substr(0, head.size()), head) << cut;
  EXPECT_EQ(cut.substr(cut.size() - std::min(cut.size(), tail.size())), tail) << cut;
}

// Hit attributes in every cache format, with Houdini's names and types where the format has
// types: hitnum an int (PLY int, VDB int32), hitpos, hitnml and hitv vec3s in VDB (three float
// columns <name>_x, _y, _z in CSV and PLY), hittime a float. Each reads back the same frame.
TEST_F(ioCollidersOnDisk, HitsGoToEveryCacheFormatWithHoudinisTypes) {
  const LoadResult loaded = parseEffect(R"(format_version = 1
[simulation]
step_rate = 240
[[emitters]]
position = [0.0, 1.0, 0.0]
rate = 20
speed = 1.0
spread = 30.0
[[forces]]
type = "gravity"
[[colliders]]
type = "plane"
restitution = 0.5
[output]
hits = true
)",
                                        "hits.toml", {});
  ASSERT_TRUE(loaded.ok());
  const EffectSettings& e = *loaded.effect;
  EXPECT_TRUE(e.output.hits);
  const auto system = buildSystem(e);
  system->stepTicks(480);
  const FrameData frame = captureFrame(*system, 48, 2.0);
  const std::vector<std::string> hitColumns(kHitColumns.begin(), kHitColumns.end());
  ASSERT_EQ(frame.attributeNames, hitColumns);
  const auto hitnum = frame.attributes[0];
  ASSERT_GT(hitnum.maxCoeff(), 1.0f) << "some particle should have bounced twice";
  EXPECT_EQ(hitnum.minCoeff(), 0.0f) << "the newest particles have not landed";

  writeCsvCache(frame, dir_ / "f.csv");
  writePlyCache(frame, dir_ / "f.ply");
  writeVdbPointCache(frame, VdbCacheMetadata{}, dir_ / "f.vdb");
  EXPECT_EQ(frameHash(readCsvCache(dir_ / "f.csv")), frameHash(frame));
  EXPECT_EQ(frameHash(readPlyCache(dir_ / "f.ply")), frameHash(frame));
  EXPECT_EQ(frameHash(readVdbPointCache(dir_ / "f.vdb")), frameHash(frame));

  std::ifstream csv(dir_ / "f.csv");
  std::string header;
  std::getline(csv, header);
  EXPECT_EQ(header,
            "id,px,py,pz,vx,vy,vz,age,life,mass,hitnum,hittime,hitpos_x,hitpos_y,hitpos_z,"
            "hitnml_x,hitnml_y,hitnml_z,hitv_x,hitv_y,hitv_z");
  const std::string head = test::fileBytes(dir_ / "f.ply");
  EXPECT_NE(head.find("property float mass\nproperty int hitnum\nproperty float hittime\n"
                      "property float hitpos_x\n"),
            std::string::npos);

  const vdb_test::PointsGridRead grid = vdb_test::readPointsGrid(dir_ / "f.vdb", "points");
  ASSERT_FALSE(grid.leaves.empty());
  std::map<std::string, std::string> types = vdb_test::attributeTypes(grid.leaves.front());
  const std::vector<std::pair<std::string, std::string>> expected = {{"hitnum", "int32"},
                                                                     {"hittime", "float"},
                                                                     {"hitpos", "vec3s"},
                                                                     {"hitnml", "vec3s"},
                                                                     {"hitv", "vec3s"}};
  for (const auto& [name, type] : expected) {
    ASSERT_TRUE(types.count(name)) << name;
    EXPECT_EQ(types[name], type) << name;
  }
  EXPECT_FALSE(types.count("hitpos_x"));
}

TEST(ioCollidersLint, HitsWithoutCollidersAreWarnedAbout) {
  const LoadResult r = parseEffect(std::string(kHead) + "[output]\nhits = true\n", "fx.toml", {});
  ASSERT_TRUE(r.ok());
  const std::vector<Diagnostic> w = lintEffect(*r.effect);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_EQ(w[0].format(),
            "fx.toml:7:8: warning: output.hits: the effect has no [[colliders]]: no particle "
            "records a hit");
}

TEST(ioColliders, HitsAreTrueOrFalse) {
  EXPECT_EQ(
      messages(R"([[colliders]]
type = "plane"
hits = "yes"
[output]
hits = 1
)"),
      (Lines{"bad.toml:8:8: error: colliders.0.hits: got a string \"yes\" (expected true "
             "or false)",
             "bad.toml:10:8: error: output.hits: got the integer 1 (expected true or false)"}));
}

TEST(ioMeshFile, PlyAsciiAndBinaryReadTheSameTriangles) {
  const std::string ascii =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
      "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  const TriangleMesh a = parseMesh(ascii, "a.ply");
  std::string binary =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\nelement face 1\n"
      "property list uchar int vertex_indices\nend_header\n";
  const float v[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  binary.append(reinterpret_cast<const char*>(v), sizeof v);
  binary.push_back(3);
  const std::int32_t f[3] = {0, 1, 2};
  binary.append(reinterpret_cast<const char*>(f), sizeof f);
  const TriangleMesh b = parseMesh(binary, "b.ply");
  ASSERT_EQ(a.points.size(), 3u);
  ASSERT_EQ(a.triangles.size(), 1u);
  EXPECT_EQ(a.points, b.points);
  EXPECT_EQ(a.triangles, b.triangles);
  EXPECT_THROW(parseMesh(binary.substr(0, binary.size() - 2), "c.ply"), std::runtime_error);
}

// fuzz_mesh: a property line too short to name its type read the last of no properties.
TEST(ioMeshFile, APropertyLineWithoutTypeAndNameIsRefused) {
  try {
    parseMesh("ply\nformat ascii 1.0\nelement vertex 1\nproperty float\nend_header\n0\n", "d.ply");
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(),
                 "d.ply: has a property line without a type and a name (expected property TYPE "
                 "NAME or property list COUNT_TYPE TYPE NAME)");
  }
}

}  // namespace
}  // namespace tickfx::io

namespace tickfx::io {
namespace {

// The lint's warnings about colliders: every message, with the numbers that fix it.
std::vector<std::string> lintOf(const std::string& text) {
  const LoadResult result = parseEffect(text, "lint.toml", {});
  EXPECT_TRUE(result.ok()) << (result.diagnostics.empty() ? "" : result.diagnostics[0].format());
  std::vector<std::string> out;
  if (!result.ok()) return out;
  for (const Diagnostic& d : lintEffect(*result.effect)) out.push_back(d.format());
  return out;
}

TEST(ioCollidersLint, AnEmitterBornInsideAColliderIsWarnedAbout) {
  EXPECT_EQ(lintOf(R"(format_version = 1
[simulation]
step_rate = 60
[[emitters]]
name = "inside"
position = [0.0, 1.0, 0.0]
shape = "box"
size = [0.2, 0.2, 0.2]
rate = 10
[[emitters]]
name = "half"
position = [0.0, 1.9, 0.0]
shape = "sphere"
radius = 0.5
rate = 10
[[colliders]]
type = "plane"
[[colliders]]
type = "sphere"
center = [0.0, 1.0, 0.0]
radius = 1.0
)"),
            (std::vector<std::string>{
                "lint.toml:6:12: warning: emitters.0.position: every particle of emitter "
                "\"inside\" starts inside colliders.1 (a sphere): its first tick puts them on the "
                "collider's surface (move the emitter or the collider)"}));
}

TEST(ioCollidersLint, ALevelSetCoarserThanItsParticlesOrFasterThanAVoxelATick) {
  EXPECT_EQ(lintOf(R"(format_version = 1
[simulation]
step_rate = 24
[[emitters]]
position = [0.0, 5.0, 0.0]
rate = 10
[[colliders]]
type = "level_set"
bake = { shape = "sphere", radius = 1.0, voxel_size = 0.1 }
radius = 0.05
velocity = [3.0, 0.0, 0.0]
)"),
            (std::vector<std::string>{
                "lint.toml:7:1: warning: colliders.0: the level set's voxel (0.1 m) is coarser "
                "than the particles' radius (0.05 m): contacts are found to within a voxel (use a "
                "voxel_size of at most 0.05 m)",
                "lint.toml:7:1: warning: colliders.0: the level set moves up to 3 m/s, 0.125 m a "
                "tick, more than a voxel (0.1 m): its contacts are found on the tick's straight "
                "path only (use a step_rate of at least 30 Hz)"}));
}

TEST(ioCollidersLint, ALevelSetThatCannotBeMadeIsWarnedAboutWithItsMessage) {
  const std::vector<std::string> w = lintOf(R"(format_version = 1
[simulation]
step_rate = 60
[[emitters]]
rate = 10
[[colliders]]
type = "level_set"
mesh = "no/such/rock.obj"
voxel_size = 0.1
)");
  EXPECT_EQ(w, (std::vector<std::string>{
                   "lint.toml:8:8: warning: colliders.0.mesh: no/such/rock.obj: no such file "
                   "(expected an OBJ or PLY triangle mesh) (tickfx run stops at this)"}));
}

}  // namespace
}  // namespace tickfx::io
