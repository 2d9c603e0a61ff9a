// [[forces]] of type "vector_field": reading every key and its errors, the advection rules,
// overrides, the lint's warnings (a file that does not load, the CFL condition), and the builder
// (files loaded relative to the effect, bakes in memory with the bits of baked files, load errors
// located at the force's key), and the samples that use fields. Every .vdb file is written into
// a temporary directory of the test.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "fields/vdb/AnalyticField.h"
#include "io/effect/EffectBuilder.h"
#include "io/effect/EffectLint.h"
#include "io/effect/EffectParser.h"
#include "io/effect/VectorFieldSource.h"
#include "particles/StateHash.h"

namespace tickfx::io {
namespace {

namespace fs = std::filesystem;
using Lines = std::vector<std::string>;

// An effect of one particle at the origin and `forces` (TOML text from "[[forces]]" on, which
// starts at line 6).
std::string effectWith(const std::string& forces) {
  return "format_version = 1\n"
         "[simulation]\n"
         "step_rate = 60\n"
         "[[emitters]]\n"
         "bursts = [{ time = 0.0, count = 1 }]\n" +
         forces;
}

// One vector_field force (line 6 its header, line 7 its type, its keys from line 8).
std::string fieldEffect(const std::string& keys) {
  return effectWith("[[forces]]\ntype = \"vector_field\"\n" + keys);
}

Lines messages(const std::string& text, const std::vector<std::string>& overrides = {}) {
  const LoadResult result = parseEffect(text, "fx.toml", overrides);
  Lines out;
  for (const Diagnostic& d : result.diagnostics) out.push_back(d.format());
  if (!out.empty()) {
    EXPECT_FALSE(result.ok()) << "errors but an effect";
  }
  return out;
}

EffectSettings load(const std::string& text, const std::string& file = "fx.toml",
                    const std::vector<std::string>& overrides = {}) {
  const LoadResult result = parseEffect(text, file, overrides);
  for (const Diagnostic& d : result.diagnostics) ADD_FAILURE() << d.format();
  return result.ok() ? *result.effect : EffectSettings{};
}

const VectorFieldSettings& fieldOf(const EffectSettings& effect, std::size_t i = 0) {
  static const VectorFieldSettings none;
  if (i >= effect.forces.size()) {
    ADD_FAILURE() << "no force " << i;
    return none;
  }
  const auto* field = std::get_if<VectorFieldSettings>(&effect.forces[i]);
  if (field == nullptr) {
    ADD_FAILURE() << "force " << i << " is not a vector_field";
    return none;
  }
  return *field;
}

Lines lint(const EffectSettings& effect) {
  Lines out;
  for (const Diagnostic& d : lintEffect(effect)) {
    EXPECT_EQ(d.severity, Severity::Warning);
    out.push_back(d.format());
  }
  return out;
}

class ioVectorField : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("tickfx_iovf_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "fields");
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  // Writes the effect into the test's directory and loads it from there (files relative to it).
  EffectSettings loadFile(const std::string& text,
                          const std::vector<std::string>& overrides = {}) const {
    const std::string file = path("fx.toml");
    std::ofstream(file) << text;
    const LoadResult result = loadEffectFile(file, overrides);
    for (const Diagnostic& d : result.diagnostics) ADD_FAILURE() << d.format();
    return result.ok() ? *result.effect : EffectSettings{};
  }

  fs::path dir_;
};

// ---- reading ----------------------------------------------------------------------------------

TEST(ioVectorFieldParse, AFileEntryGetsTheDocumentedDefaults) {
  const EffectSettings effect = load(fieldEffect("file = \"fields/wind.vdb\"\n"), "shots/fx.toml");
  const VectorFieldSettings& f = fieldOf(effect);
  EXPECT_EQ(f.file, "fields/wind.vdb");
  EXPECT_EQ(f.path, "shots/fields/wind.vdb");  // relative to the effect file's directory
  EXPECT_FALSE(f.bake.has_value());
  EXPECT_EQ(f.grid, "vel");
  EXPECT_EQ(f.mode, VectorField::Mode::Force);
  EXPECT_EQ(f.scale, 1.0);
  EXPECT_EQ(f.interpolation, VectorField::Interpolation::Linear);
  EXPECT_EQ(f.outside, VectorField::Outside::Background);
  EXPECT_EQ(f.fps, 0.0);
  EXPECT_EQ(f.framePadding, 4);
  EXPECT_EQ(forceTypeName(effect.forces[0]), "vector_field");
  // An absolute path is taken as it is; a bare effect name resolves in the working directory.
  EXPECT_EQ(fieldOf(load(fieldEffect("file = \"/data/wind.vdb\"\n"), "shots/fx.toml")).path,
            "/data/wind.vdb");
  EXPECT_EQ(fieldOf(load(fieldEffect("file = \"wind.vdb\"\n"))).path, "wind.vdb");
}

TEST(ioVectorFieldParse, EveryKeyOfASequenceIsRead) {
  const VectorFieldSettings f = fieldOf(load(fieldEffect(R"(file = "sim/vel.{frame}.vdb"
grid = "v"
mode = "drag"
scale = 2.5
interpolation = "quadratic"
outside = "kill"
fps = 24
first_frame = -2
last_frame = 30
frame_padding = 3
)")));
  EXPECT_EQ(f.path, "sim/vel.{frame}.vdb");
  EXPECT_EQ(f.grid, "v");
  EXPECT_EQ(f.mode, VectorField::Mode::Drag);
  EXPECT_EQ(f.scale, 2.5);
  EXPECT_EQ(f.interpolation, VectorField::Interpolation::Quadratic);
  EXPECT_EQ(f.outside, VectorField::Outside::Kill);
  EXPECT_EQ(f.fps, 24.0);
  EXPECT_EQ(f.firstFrame, -2);
  EXPECT_EQ(f.lastFrame, 30);
  EXPECT_EQ(f.framePadding, 3);
  EXPECT_EQ(sequenceFramePath(f.path, -2, 3), "sim/vel.-002.vdb");
  EXPECT_EQ(sequenceFramePath(f.path, 30, 3), "sim/vel.030.vdb");
  // Without first_frame a sequence starts at frame 1.
  EXPECT_EQ(fieldOf(load(fieldEffect("file = \"v{frame}.vdb\"\nfps = 12.5\nlast_frame = 4\n")))
                .firstFrame,
            1);
}

TEST(ioVectorFieldParse, EveryKeyOfEachBakeKindIsRead) {
  const auto bakeOf = [](const std::string& table) {
    const VectorFieldSettings f = fieldOf(load(fieldEffect("bake = " + table + "\n")));
    EXPECT_TRUE(f.file.empty());
    return f.bake.value_or(FieldBakeSettings{});
  };
  const FieldBakeSettings defaults = bakeOf("{ kind = \"uniform\" }");
  EXPECT_EQ(defaults.kind, FieldBakeSettings::Kind::Uniform);
  EXPECT_EQ(defaults.voxelSize, 0.1);
  EXPECT_EQ(defaults.min, Eigen::Vector3d::Constant(-1.0));
  EXPECT_EQ(defaults.max, Eigen::Vector3d::Constant(1.0));
  EXPECT_FALSE(defaults.staggered);
  EXPECT_EQ(defaults.background, Eigen::Vector3d::Zero());
  EXPECT_EQ(defaults.velocity, Eigen::Vector3d(1.0, 0.0, 0.0));

  const FieldBakeSettings uniform = bakeOf(
      "{ kind = \"uniform\", velocity = [1, 2, 3], voxel_size = 0.25, bounds = [-1, 0, "
      "-2, 1, 4, 2], staggered = true, background = [0.5, 0, 0] }");
  EXPECT_EQ(uniform.velocity, Eigen::Vector3d(1.0, 2.0, 3.0));
  EXPECT_EQ(uniform.voxelSize, 0.25);
  EXPECT_EQ(uniform.min, Eigen::Vector3d(-1.0, 0.0, -2.0));
  EXPECT_EQ(uniform.max, Eigen::Vector3d(1.0, 4.0, 2.0));
  EXPECT_TRUE(uniform.staggered);
  EXPECT_EQ(uniform.background, Eigen::Vector3d(0.5, 0.0, 0.0));

  const FieldBakeSettings vortex =
      bakeOf("{ kind = \"vortex\", centre = [1, 0, 0], axis = [0, 0, 2], omega = -1.5 }");
  EXPECT_EQ(vortex.kind, FieldBakeSettings::Kind::Vortex);
  EXPECT_EQ(vortex.centre, Eigen::Vector3d(1.0, 0.0, 0.0));
  EXPECT_EQ(vortex.axis, Eigen::Vector3d(0.0, 0.0, 2.0));
  EXPECT_EQ(vortex.omega, -1.5);

  const FieldBakeSettings shear = bakeOf(
      "{ kind = \"shear\", origin = [0, 1, 0], direction = [0, 0, 1], gradient = [1, 0, 0], rate = "
      "0.5 }");
  EXPECT_EQ(shear.kind, FieldBakeSettings::Kind::Shear);
  EXPECT_EQ(shear.origin, Eigen::Vector3d(0.0, 1.0, 0.0));
  EXPECT_EQ(shear.direction, Eigen::Vector3d(0.0, 0.0, 1.0));
  EXPECT_EQ(shear.gradient, Eigen::Vector3d(1.0, 0.0, 0.0));
  EXPECT_EQ(shear.rate, 0.5);

  const FieldBakeSettings noise = bakeOf(
      "{ kind = \"curl-noise\", seed = 12, frequency = 2, amplitude = 0.5, octaves = 2, "
      "evolution = 0.25 }");
  EXPECT_EQ(noise.kind, FieldBakeSettings::Kind::CurlNoise);
  EXPECT_EQ(noise.seed, 12u);
  EXPECT_EQ(noise.frequency, 2.0);
  EXPECT_EQ(noise.amplitude, 0.5);
  EXPECT_EQ(noise.octaves, 2);
  EXPECT_EQ(noise.evolution, 0.25);

  // A bake table may be written as a sub-table too, and a baked sequence needs no pattern.
  const VectorFieldSettings sequence = fieldOf(load(fieldEffect(
      "fps = 2\nfirst_frame = 0\nlast_frame = 4\n[forces.bake]\nkind = \"curl-noise\"\n")));
  ASSERT_TRUE(sequence.bake.has_value());
  EXPECT_EQ(sequence.bake->kind, FieldBakeSettings::Kind::CurlNoise);
  EXPECT_EQ(sequence.lastFrame, 4);
}

TEST(ioVectorFieldParse, FileOrBakeExactlyOnce) {
  EXPECT_EQ(messages(fieldEffect("mode = \"drag\"\n")),
            (Lines{"fx.toml:6:1: error: forces.0.file: missing (expected a .vdb file path "
                   "relative to the effect file's directory, a non-empty string, or a bake "
                   "table)"}));
  EXPECT_EQ(messages(fieldEffect("file = \"a.vdb\"\nbake = { kind = \"uniform\" }\n")),
            (Lines{"fx.toml:9:8: error: forces.0.bake: given together with file (expected either "
                   "file or bake)"}));
  EXPECT_EQ(
      messages(fieldEffect("file = \"\"\nbake = \"vortex\"\n")),
      (Lines{"fx.toml:8:8: error: forces.0.file: got an empty string (expected a .vdb file path "
             "relative to the effect file's directory, a non-empty string)",
             "fx.toml:9:8: error: forces.0.bake: got a string \"vortex\" (expected a bake table "
             "such as { kind = \"vortex\", voxel_size = 0.1 })",
             "fx.toml:9:8: error: forces.0.bake: given together with file (expected either file "
             "or bake)"}));
}

TEST(ioVectorFieldParse, ChoicesAndScale) {
  EXPECT_EQ(
      messages(fieldEffect("file = \"a.vdb\"\nmode = \"advection\"\ninterpolation = "
                           "\"cubic\"\noutside = \"clamp\"\ngrid = 3\n")),
      (Lines{"fx.toml:9:8: error: forces.0.mode: unknown field mode \"advection\" (did you mean "
             "\"advect\"?)",
             "fx.toml:10:17: error: forces.0.interpolation: unknown interpolation \"cubic\" "
             "(expected one of: linear, quadratic)",
             "fx.toml:11:11: error: forces.0.outside: unknown outside policy \"clamp\" (expected "
             "one of: background, zero, kill)",
             "fx.toml:12:8: error: forces.0.grid: got the integer 3 (expected a grid name, a "
             "non-empty string)"}));
  EXPECT_EQ(messages(fieldEffect("file = \"a.vdb\"\nmode = \"drg\"\n")),
            (Lines{"fx.toml:9:8: error: forces.0.mode: unknown field mode \"drg\" (did you mean "
                   "\"drag\"?)"}));
  // Drag's scale is a rate: never negative. The other modes may flip the field.
  EXPECT_EQ(messages(fieldEffect("file = \"a.vdb\"\nmode = \"drag\"\nscale = -1\n")),
            (Lines{"fx.toml:10:9: error: forces.0.scale: -1 is out of range (expected a rate k in "
                   "1/s for mode \"drag\", a number from 0 to 1e9)"}));
  EXPECT_EQ(messages(fieldEffect("file = \"a.vdb\"\nscale = nan\n")),
            (Lines{"fx.toml:9:9: error: forces.0.scale: nan is not a finite number (expected "
                   "m/s² per unit of the field for mode \"force\", a number from -1e9 to 1e9)"}));
  EXPECT_EQ(fieldOf(load(fieldEffect("file = \"a.vdb\"\nscale = -2\n"))).scale, -2.0);
}

TEST(ioVectorFieldParse, SequenceErrors) {
  EXPECT_EQ(messages(fieldEffect("file = \"a.vdb\"\nfirst_frame = 1\nframe_padding = 2\n")),
            (Lines{"fx.toml:9:15: error: forces.0.first_frame: given without fps (expected fps, "
                   "first_frame and last_frame for a sequence)",
                   "fx.toml:10:17: error: forces.0.frame_padding: given without fps (expected fps, "
                   "first_frame and last_frame for a sequence)"}));
  EXPECT_EQ(messages(fieldEffect("file = \"a.vdb\"\nfps = 24\n")),
            (Lines{"fx.toml:6:1: error: forces.0.last_frame: missing (expected the last frame of "
                   "the sequence, an integer from first_frame to 1000000)",
                   "fx.toml:8:8: error: forces.0.file: \"a.vdb\" has no {frame} (expected a file "
                   "pattern with {frame} for a sequence, since fps is given)"}));
  EXPECT_EQ(messages(fieldEffect("file = \"a.{frame}.vdb\"\n")),
            (Lines{"fx.toml:8:8: error: forces.0.file: \"a.{frame}.vdb\" has {frame} but fps is "
                   "not given (expected fps, first_frame and last_frame for a sequence, or a file "
                   "name without {frame})"}));
  EXPECT_EQ(
      messages(
          fieldEffect("file = \"a.{frame}.vdb\"\nfps = 0\nfirst_frame = 5\nlast_frame = 4.0\n")),
      (Lines{"fx.toml:9:7: error: forces.0.fps: 0 is out of range (expected frames per second, a "
             "number from 1e-6 to 1000000)",
             "fx.toml:11:14: error: forces.0.last_frame: 4.0 is not an integer (expected a frame "
             "number, an integer from -1000000 to 1000000)"}));
  EXPECT_EQ(
      messages(fieldEffect("file = \"a.{frame}.vdb\"\nfps = 1\nfirst_frame = 5\nlast_frame = 4\n")),
      (Lines{"fx.toml:11:14: error: forces.0.last_frame: 4 is before first_frame = 5 (expected "
             "the last frame of the sequence, an integer from first_frame to 1000000)"}));
  EXPECT_EQ(messages(fieldEffect(
                "file = \"a.{frame}.vdb\"\nfps = 1\nfirst_frame = 0\nlast_frame = 10000\n")),
            (Lines{"fx.toml:11:14: error: forces.0.last_frame: 10001 frames are too many (expected "
                   "at most 10000 frames in a sequence)"}));
  EXPECT_EQ(
      messages(
          fieldEffect("file = \"a.{frame}.vdb\"\nfps = 1\nlast_frame = 2\nframe_padding = 11\n")),
      (Lines{"fx.toml:11:17: error: forces.0.frame_padding: 11 is out of range (expected digits, "
             "an integer from 1 to 10)"}));
  // A bake has no files: neither a grid name nor a padding.
  EXPECT_EQ(
      messages(fieldEffect("bake = { kind = \"uniform\" }\ngrid = \"v\"\nfps = 1\nlast_frame = "
                           "2\nframe_padding = 2\n")),
      (Lines{"fx.toml:9:8: error: forces.0.grid: does not apply to a baked field (expected grid "
             "only with file: a bake makes its own grid)",
             "fx.toml:12:17: error: forces.0.frame_padding: does not apply to a baked field "
             "(expected frame_padding only with a file pattern)"}));
}

TEST(ioVectorFieldParse, BakeDirectionsMustNormaliseInDouble) {
  // AnalyticField normalises a vortex's axis and a shear's direction and gradient in double;
  // vectors too short for that used to pass check (which then failed, exit 1, loading the field
  // for its lint) and stop run with exit 1 and no position.
  EXPECT_EQ(messages(fieldEffect("mode = \"drag\"\nbake = { kind = \"vortex\", axis = [0, "
                                 "1e-200, 0] }\n")),
            (Lines{"fx.toml:9:34: error: forces.0.bake.axis: is too short to normalise in double "
                   "precision (expected a direction [x, y, z] at least 1.5e-154 long)"}));
  EXPECT_EQ(messages(fieldEffect("bake = { kind = \"shear\", direction = [1e-200, 0, 0], "
                                 "gradient = [0, 1e-170, 0] }\n")),
            (Lines{"fx.toml:8:38: error: forces.0.bake.direction: is too short to normalise in "
                   "double precision (expected a direction [x, y, z] at least 1.5e-154 long)",
                   "fx.toml:8:65: error: forces.0.bake.gradient: is too short to normalise in "
                   "double precision (expected a direction [x, y, z] at least 1.5e-154 long)"}));
  // Through an override, the message names it.
  EXPECT_EQ(messages(fieldEffect("bake = { kind = \"vortex\" }\n"), {"forces.0.bake.axis=[0, 0, "
                                                                     "1e-300]"}),
            (Lines{"--set forces.0.bake.axis: error: forces.0.bake.axis: is too short to "
                   "normalise in double precision (expected a direction [x, y, z] at least "
                   "1.5e-154 long)"}));
}

TEST(ioVectorFieldParse, BakeErrors) {
  EXPECT_EQ(messages(fieldEffect("bake = { omega = 1 }\n")),
            (Lines{"fx.toml:8:8: error: forces.0.bake.kind: missing (expected field kind, one of: "
                   "uniform, vortex, shear, curl-noise)"}));
  EXPECT_EQ(
      messages(fieldEffect("bake = { kind = \"curl_noise\" }\n")),
      (Lines{"fx.toml:8:17: error: forces.0.bake.kind: unknown field kind \"curl_noise\" (did "
             "you mean \"curl-noise\"?)"}));
  EXPECT_EQ(
      messages(fieldEffect("bake = { kind = \"vortex\", rate = 2, omga = 1, axis = [0, 0, 0] }\n")),
      (Lines{"fx.toml:8:27: error: forces.0.bake.rate: does not apply to a bake of kind "
             "\"vortex\" (expected for vortex: kind, voxel_size, bounds, staggered, background, "
             "centre, axis, omega)",
             "fx.toml:8:37: error: forces.0.bake.omga: unknown key \"omga\" (did you mean "
             "\"omega\"?)",
             "fx.toml:8:54: error: forces.0.bake.axis: got [0, 0, 0] (expected a direction [x, y, "
             "z], each from -1e9 to 1e9, not all zero)"}));
  EXPECT_EQ(
      messages(fieldEffect("bake = { kind = \"curl-noise\", frequency = 0, octaves = 17, "
                           "amplitude = -1, evolution = -0.5, seed = -1 }\n")),
      (Lines{"fx.toml:8:43: error: forces.0.bake.frequency: 0 is out of range (expected radians "
             "per metre, a number > 0 and <= 1e9)",
             "fx.toml:8:56: error: forces.0.bake.octaves: 17 is out of range (expected an "
             "integer from 1 to 16)",
             "fx.toml:8:72: error: forces.0.bake.amplitude: -1 is out of range (expected m/s, a "
             "number from 0 to 1e9)",
             "fx.toml:8:88: error: forces.0.bake.evolution: -0.5 is out of range (expected "
             "radians per second, a number from 0 to 1e9)",
             "fx.toml:8:101: error: forces.0.bake.seed: -1 is out of range (expected an integer "
             "from 0 to 9223372036854775807)"}));
}

TEST(ioVectorFieldParse, BakeBoundsAndSize) {
  const std::string boundsText =
      "(expected [x0, y0, z0, x1, y1, z1] in metres, each from -1e9 to 1e9, with x0 <= x1, y0 <= "
      "y1 and z0 <= z1)";
  EXPECT_EQ(messages(fieldEffect("bake = { kind = \"uniform\", bounds = [0, 0, 0, 1, 1] }\n")),
            (Lines{"fx.toml:8:37: error: forces.0.bake.bounds: got 5 entries " + boundsText}));
  EXPECT_EQ(messages(fieldEffect("bake = { kind = \"uniform\", bounds = [0, 2, 0, 1, 1, inf] }\n")),
            (Lines{"fx.toml:8:53: error: forces.0.bake.bounds.5: inf is not a finite number " +
                   boundsText}));
  EXPECT_EQ(
      messages(fieldEffect("bake = { kind = \"uniform\", bounds = [0, 2, 0, 1, 1, 1] }\n")),
      (Lines{"fx.toml:8:50: error: forces.0.bake.bounds.4: y1 = 1 is below y0 = 2 " + boundsText}));
  EXPECT_EQ(messages(fieldEffect("bake = { kind = \"uniform\", voxel_size = 0 }\n")),
            (Lines{"fx.toml:8:41: error: forces.0.bake.voxel_size: 0 is out of range (expected "
                   "metres, a number > 0 and <= 1e9)"}));
  // The box must hold a voxel centre i·h on every axis.
  EXPECT_EQ(
      messages(fieldEffect(
          "bake = { kind = \"uniform\", voxel_size = 1, bounds = [0.1, 0, 0, 0.9, 1, 1] }\n")),
      (Lines{"fx.toml:8:53: error: forces.0.bake.bounds: hold no voxel centre at voxel_size = 1 "
             "m (expected a box holding at least one point i*voxel_size on each axis)"}));
  // 2001³ voxels, and the same grid over three frames; then indices past OpenVDB's coordinates.
  EXPECT_EQ(messages(fieldEffect("bake = { kind = \"uniform\", voxel_size = 0.001 }\n")),
            (Lines{"fx.toml:8:41: error: forces.0.bake.voxel_size: 0.001 m makes 8012006001 voxels "
                   "a frame, 8012006001 over 1 frame (expected at most 100000000 voxels over all "
                   "frames: a larger voxel_size, smaller bounds or fewer frames)"}));
  // 4000 x 4000 x 1 voxels a frame: within the bound over 6 frames, past it over 7.
  const std::string flat =
      "bake = { kind = \"uniform\", voxel_size = 0.125, bounds = [0, 0, 0, "
      "499.9, 499.9, 0] }\n";
  EXPECT_TRUE(messages(fieldEffect("fps = 1\nlast_frame = 6\n" + flat)).empty());
  EXPECT_EQ(
      messages(fieldEffect("fps = 1\nlast_frame = 7\n" + flat)),
      (Lines{"fx.toml:10:41: error: forces.0.bake.voxel_size: 0.125 m makes 16000000 voxels a "
             "frame, 112000000 over 7 frames (expected at most 100000000 voxels over all frames: "
             "a larger voxel_size, smaller bounds or fewer frames)"}));
  EXPECT_EQ(
      messages(fieldEffect(
          "bake = { kind = \"uniform\", voxel_size = 1e-9, bounds = [0, 0, 0, 1e-9, 1e-9, 2] }\n")),
      (Lines{"fx.toml:8:41: error: forces.0.bake.voxel_size: 1e-09 m puts the bounds 2000000000 "
             "voxels from the origin (expected a voxel_size of at least 2e-09 m for these bounds: "
             "voxel indices within 1e9)"}));
}

TEST(ioVectorFieldParse, KeysOfOtherForceTypes) {
  EXPECT_EQ(messages(fieldEffect("file = \"a.vdb\"\nk = 2\n")),
            (Lines{"fx.toml:9:1: error: forces.0.k: does not apply to a force of type "
                   "\"vector_field\" (expected for vector_field: type, file, bake, grid, mode, "
                   "scale, interpolation, outside, fps, first_frame, last_frame, frame_padding)"}));
  EXPECT_EQ(messages(effectWith("[[forces]]\ntype = \"drag\"\nk = 1\nmode = \"drag\"\n")),
            (Lines{"fx.toml:9:1: error: forces.0.mode: does not apply to a force of type \"drag\" "
                   "(expected for drag: type, k, air_velocity)"}));
  EXPECT_EQ(messages(fieldEffect("file = \"a.vdb\"\nscael = 2\n")),
            (Lines{"fx.toml:9:1: error: forces.0.scael: unknown key \"scael\" (did you mean "
                   "\"scale\"?)"}));
}

// ---- advection ------------------------------------------------------------------------------

TEST(ioVectorFieldParse, AdvectionCannotBeMixedWithOtherForcesOrStructures) {
  const std::string advect =
      "[[forces]]\ntype = \"vector_field\"\nmode = \"advect\"\nbake = { kind = \"vortex\" }\n";
  EXPECT_EQ(
      messages(effectWith("[[forces]]\ntype = \"gravity\"\n" + advect)),
      (Lines{"fx.toml:10:8: error: forces.1.mode: \"advect\" sets the particles' velocity to the "
             "field's, so forces.0 (gravity) would be ignored (expected mode = \"drag\", which "
             "pulls the particles toward the field's velocity alongside other forces, or advect "
             "fields as the only forces of an effect without structures)"}));
  // A structure's springs are forces too; so is a field in another mode.
  const std::string rope =
      "[[emitters]]\ntype = \"rope\"\nend = [1.0, 0.0, 0.0]\ncount = 4\nstiffness = 10.0\n";
  EXPECT_EQ(
      messages(effectWith(rope + advect +
                          "[[forces]]\ntype = \"vector_field\"\nfile = "
                          "\"b.vdb\"\nmode = \"drag\"\n")),
      (Lines{"fx.toml:13:8: error: forces.0.mode: \"advect\" sets the particles' velocity to the "
             "field's, so forces.1 (vector_field) and emitters.1 (the springs of a rope) would "
             "all be ignored (expected mode = \"drag\", which pulls the particles toward the "
             "field's velocity alongside other forces, or advect fields as the only forces of an "
             "effect without structures)"}));
  // Long lists are cut short.
  std::string many;
  for (int i = 0; i < 5; ++i) many += "[[forces]]\ntype = \"gravity\"\n";
  const Lines cut = messages(effectWith(advect + many));
  ASSERT_EQ(cut.size(), 1u);
  EXPECT_NE(cut[0].find("so forces.1 (gravity), forces.2 (gravity), forces.3 (gravity) and 2 more "
                        "would all be ignored"),
            std::string::npos)
      << cut[0];
  // Advect fields alone are fine: their velocities add.
  const EffectSettings two = load(effectWith(advect + advect));
  EXPECT_EQ(two.forces.size(), 2u);
  // An override that makes the mix names the override.
  EXPECT_EQ(
      messages(effectWith("[[forces]]\ntype = \"gravity\"\n[[forces]]\ntype = "
                          "\"vector_field\"\nbake = { kind = \"vortex\" }\n"),
               {"forces.1.mode=advect"}),
      (Lines{"--set forces.1.mode: error: forces.1.mode: \"advect\" sets the particles' velocity "
             "to the field's, so forces.0 (gravity) would be ignored (expected mode = \"drag\", "
             "which pulls the particles toward the field's velocity alongside other forces, or "
             "advect fields as the only forces of an effect without structures)"}));
}

// ---- overrides --------------------------------------------------------------------------------

TEST(ioVectorFieldParse, OverridesReachEveryKeyOfAField) {
  const std::string text = fieldEffect(
      "file = \"a.vdb\"\n[[forces]]\ntype = \"vector_field\"\nbake = { kind = "
      "\"vortex\", omega = 1.0 }\n");
  const EffectSettings effect =
      load(text, "fx.toml",
           {"forces.0.scale=2.5", "forces.0.mode=drag", "forces.0.grid=v", "forces.0.file=b.vdb",
            "forces.0.interpolation=quadratic", "forces.0.outside=kill", "forces.1.bake.omega=3",
            "forces.1.bake.voxel_size=0.25", "forces.1.bake.bounds=[0, 0, 0, 1, 1, 1]",
            "forces.1.fps=2", "forces.1.last_frame=3"});
  const VectorFieldSettings& a = fieldOf(effect, 0);
  EXPECT_EQ(a.scale, 2.5);
  EXPECT_EQ(a.mode, VectorField::Mode::Drag);
  EXPECT_EQ(a.grid, "v");
  EXPECT_EQ(a.path, "b.vdb");
  EXPECT_EQ(a.interpolation, VectorField::Interpolation::Quadratic);
  EXPECT_EQ(a.outside, VectorField::Outside::Kill);
  const VectorFieldSettings& b = fieldOf(effect, 1);
  ASSERT_TRUE(b.bake.has_value());
  EXPECT_EQ(b.bake->omega, 3.0);
  EXPECT_EQ(b.bake->voxelSize, 0.25);
  EXPECT_EQ(b.bake->max, Eigen::Vector3d::Ones());
  EXPECT_EQ(b.fps, 2.0);
  EXPECT_EQ(b.lastFrame, 3);
  // Overridden values are judged like written ones, and their messages name the override (a key
  // written in the file that no longer applies is shown where it is written).
  EXPECT_EQ(messages(text, {"forces.1.bake.kind=shear", "forces.0.scale=inf"}),
            (Lines{"fx.toml:11:27: error: forces.1.bake.omega: does not apply to a bake of kind "
                   "\"shear\" (expected for shear: kind, voxel_size, bounds, "
                   "staggered, background, origin, direction, gradient, rate)",
                   "--set forces.0.scale: error: forces.0.scale: inf is not a finite number "
                   "(expected m/s² per unit of the field for mode \"force\", a number from -1e9 "
                   "to 1e9)"}));
  EXPECT_EQ(messages(text, {"forces.0.bake.kind=uniform"}),
            (Lines{"--set forces.0.bake.kind: error: forces.0.bake: given together with file "
                   "(expected either file or bake)"}));
}

// Regression (issue 10, item 12): every bake of a file went through the one temporary
// PATH.partial, so two bakes of one file at once wrote into each other's. Eight at once now all
// succeed and leave one whole file and no temporary.
TEST_F(ioVectorField, BakesOfOneFileAtOnceDoNotShareATemporary) {
  fs::create_directories(path("fields"));
  std::vector<std::thread> bakes;
  std::atomic<int> failed{0};
  for (int i = 0; i < 8; ++i) {
    bakes.emplace_back([&, i] {
      try {
        bakeField(AnalyticField::uniform({1.0 + i, 0.0, 0.0}), BakeSettings{},
                  path("fields/same.vdb"));
      } catch (const std::exception&) {
        ++failed;
      }
    });
  }
  for (std::thread& t : bakes) t.join();
  EXPECT_EQ(failed.load(), 0);
  int files = 0;
  for (const auto& entry : fs::directory_iterator(path("fields"))) {
    ++files;
    EXPECT_EQ(entry.path().filename(), "same.vdb") << "a temporary was left behind";
  }
  EXPECT_EQ(files, 1);
  VectorField::Settings s;
  s.file = path("fields/same.vdb");
  const float x = VectorField(s).sample(Eigen::Vector3f::Zero()).x();
  EXPECT_TRUE(x >= 1.0f && x <= 8.0f && x == std::floor(x)) << "one whole bake: " << x;
}

// ---- lint -------------------------------------------------------------------------------------

TEST_F(ioVectorField, LintWarnsAboutAFileThatDoesNotLoad) {
  const EffectSettings effect = loadFile(fieldEffect("file = \"fields/none.vdb\"\n"));
  EXPECT_EQ(lint(effect),
            (Lines{path("fx.toml") + ":8:8: warning: forces.0.file: " + path("fields/none.vdb") +
                   ": grid 'vel': no such file (tickfx run stops at this: write the file first, "
                   "e.g. with tickfx bake-field, or correct file and grid)"}));
  // A grid the file does not have.
  bakeField(AnalyticField::uniform({1.0, 0.0, 0.0}), BakeSettings{}, path("fields/u.vdb"));
  EXPECT_EQ(lint(loadFile(fieldEffect("file = \"fields/u.vdb\"\ngrid = \"velocity\"\n"))),
            (Lines{path("fx.toml") + ":8:8: warning: forces.0.file: " + path("fields/u.vdb") +
                   ": grid 'velocity': no such grid (the file has: vel) (tickfx run stops at "
                   "this: write the file first, e.g. with tickfx bake-field, or correct file and "
                   "grid)"}));
  // A sequence names the first frame that is missing.
  bakeField(AnalyticField::uniform({1.0, 0.0, 0.0}), BakeSettings{}, path("fields/s.0001.vdb"));
  EXPECT_EQ(
      lint(loadFile(fieldEffect("file = \"fields/s.{frame}.vdb\"\nfps = 24\nlast_frame = 2\n"))),
      (Lines{path("fx.toml") + ":8:8: warning: forces.0.file: " + path("fields/s.0002.vdb") +
             ": grid 'vel': no such file (tickfx run stops at this: write the file first, "
             "e.g. with tickfx bake-field, or correct file and grid)"}));
  EXPECT_TRUE(lint(loadFile(fieldEffect("file = \"fields/u.vdb\"\n"))).empty());
}

// A uniform field of `speed` m/s baked at voxel size `h` in mode `mode` at `rate` Hz.
std::string cflEffect(const std::string& mode, double speed, double h, int rate,
                      double scale = 1.0) {
  // A cap no CFL case reaches: the lint's tick-cap warning is not what these tests are about.
  return "format_version = 1\n[simulation]\nstep_rate = " + std::to_string(rate) +
         "\nmax_ticks_per_frame = 100000\n[[emitters]]\nbursts = [{ time = 0.0, count = 1 "
         "}]\n[[forces]]\ntype = "
         "\"vector_field\"\nmode = \"" +
         mode + "\"\nscale = " + std::to_string(scale) +
         "\nbake = { kind = \"uniform\", velocity = [0, " + std::to_string(speed) +
         ", 0], voxel_size = " + std::to_string(h) + " }\n";
}

TEST(ioVectorFieldLint, CflNamesTheStepRateThatKeepsAStepWithinAVoxel) {
  // Advection: 12 m/s at 60 Hz is 0.2 m a step through voxels of 0.1 m: 120 Hz is the fix.
  EXPECT_EQ(lint(load(cflEffect("advect", 12.0, 0.1, 60))),
            (Lines{"fx.toml:7:1: warning: forces.0: the field carries particles up to 12 m/s, "
                   "12·dt = 0.2 m a step, more than a voxel (0.1 m) (use a step_rate of at least "
                   "120 Hz)"}));
  EXPECT_TRUE(lint(load(cflEffect("advect", 12.0, 0.1, 120))).empty());  // exactly a voxel
  // Advection's speed is scaled, whatever the scale's sign.
  EXPECT_EQ(lint(load(cflEffect("advect", 3.0, 0.125, 24, -2.0))),
            (Lines{"fx.toml:7:1: warning: forces.0: the field carries particles up to 6 m/s, "
                   "6·dt = 0.25 m a step, more than a voxel (0.125 m) (use a step_rate of at least "
                   "48 Hz)"}));
  // Drag pulls toward the field's own velocity: its scale is a rate, not a speed.
  EXPECT_EQ(lint(load(cflEffect("drag", 7.0, 0.1, 60, 5.0))),
            (Lines{"fx.toml:7:1: warning: forces.0: the field carries particles up to 7 m/s, "
                   "7·dt = 0.1167 m a step, more than a voxel (0.1 m) (use a step_rate of at least "
                   "70 Hz)"}));
  EXPECT_TRUE(lint(load(cflEffect("drag", 7.0, 0.1, 70, 5.0))).empty());
  // A force field is an acceleration: no CFL condition.
  EXPECT_TRUE(lint(load(cflEffect("force", 700.0, 0.1, 60))).empty());
}

TEST(ioVectorFieldLint, TheBuiltFieldsGiveTheSameWarningsWithoutLoadingAgain) {
  // `tickfx run` lints with the forces it built, so that a field is loaded once.
  const EffectSettings effect = load(cflEffect("advect", 12.0, 0.1, 60));
  const ForceSet built = buildForces(effect.forces);
  Lines withBuilt;
  for (const Diagnostic& d : lintEffect(effect, &built)) withBuilt.push_back(d.format());
  EXPECT_EQ(withBuilt, lint(effect));
  ASSERT_EQ(withBuilt.size(), 1u);
  // What the lint read is the built module: a different one shows.
  const EffectSettings slower = load(cflEffect("advect", 24.0, 0.1, 60));
  const ForceSet faster = buildForces(slower.forces);
  Lines fromFaster;
  for (const Diagnostic& d : lintEffect(effect, &faster)) fromFaster.push_back(d.format());
  ASSERT_EQ(fromFaster.size(), 1u);
  EXPECT_NE(fromFaster[0].find("up to 24 m/s"), std::string::npos) << fromFaster[0];
}

TEST(ioVectorFieldLint, TheNamedStepRateIsTheSmallestThatHolds) {
  for (const double speed : {0.7, 3.3, 9.99, 12.01, 47.3}) {
    for (const double h : {0.05, 0.1, 0.3}) {
      const Lines w = lint(load(cflEffect("advect", speed, h, 1)));
      ASSERT_EQ(w.size(), 1u) << speed << " " << h;
      const std::size_t at = w[0].find("at least ");
      const int needed = std::stoi(w[0].substr(at + 9));
      EXPECT_TRUE(lint(load(cflEffect("advect", speed, h, needed))).empty()) << w[0];
      if (needed > 1) {
        EXPECT_EQ(lint(load(cflEffect("advect", speed, h, needed - 1))).size(), 1u) << w[0];
      }
    }
  }
}

// ---- building ---------------------------------------------------------------------------------

std::string hashAfter(ParticleSystem& system, std::int64_t ticks) {
  system.stepTicks(ticks);
  return hashToHex(stateHash(system.pool()));
}

// Particles in a box, pulled toward a field, and the field as a file or as a bake table.
std::string swirl(const std::string& source) {
  return "format_version = 1\n[simulation]\nstep_rate = 60\nseed = 3\n[[emitters]]\nshape = "
         "\"box\"\nsize = [1.6, 1.6, 1.6]\nrate = 600.0\nspeed = 0.5\nspread = 180.0\n"
         "[[forces]]\ntype = \"gravity\"\nacceleration = [0.0, 0.5, 0.0]\n[[forces]]\ntype = "
         "\"vector_field\"\nmode = \"drag\"\nscale = 3.0\noutside = \"kill\"\n" +
         source;
}

TEST_F(ioVectorField, ABakeTableGivesTheBitsOfTheSameFieldBakedToAFile) {
  FieldBakeSettings bake;
  bake.kind = FieldBakeSettings::Kind::Vortex;
  bake.axis = {0.2, 1.0, 0.1};
  bake.omega = 2.0;
  bake.voxelSize = 0.125;
  bakeField(analyticField(bake), bakeSettings(bake), path("fields/vortex.vdb"));
  const auto fromFile = buildSystem(loadFile(swirl("file = \"fields/vortex.vdb\"\n")), 2);
  const auto baked = buildSystem(
      loadFile(swirl("bake = { kind = \"vortex\", axis = [0.2, 1.0, 0.1], omega = 2.0, voxel_size "
                     "= 0.125 }\n")),
      2);
  const std::string hash = hashAfter(*fromFile, 120);
  EXPECT_EQ(hashAfter(*baked, 120), hash);
  EXPECT_GT(fromFile->pool().size(), 100u);
  // Particles that leave the field's box die (outside = "kill"): everyone alive is inside.
  const ParticlePool& pool = fromFile->pool();
  for (std::size_t i = 0; i < pool.size(); ++i) {
    EXPECT_LE(std::abs(pool.position().y[static_cast<Eigen::Index>(i)]), 1.0625f);
  }
  EXPECT_LT(pool.size() + 1, pool.nextId()) << "some particles left the box and died";
}

TEST_F(ioVectorField, ABakedSequenceGivesTheBitsOfTheSameSequenceOfFiles) {
  FieldBakeSettings bake;
  bake.kind = FieldBakeSettings::Kind::CurlNoise;
  bake.seed = 4;
  bake.frequency = 2.0;
  bake.evolution = 3.0;
  bake.voxelSize = 0.125;
  for (int f = 3; f <= 7; ++f) {
    bakeField(analyticField(bake), bakeSettings(bake),
              sequenceFramePath(path("fields/n.{frame}.vdb"), f, 4), (f - 3) / 4.0);
  }
  const std::string frames = "fps = 4\nfirst_frame = 3\nlast_frame = 7\n";
  const auto fromFiles =
      buildSystem(loadFile(swirl(frames + "file = \"fields/n.{frame}.vdb\"\n")), 1);
  const auto baked = buildSystem(
      loadFile(swirl(frames + "bake = { kind = \"curl-noise\", seed = 4, frequency = 2.0, "
                              "evolution = 3.0, voxel_size = 0.125 }\n")),
      1);
  const std::string hash = hashAfter(*fromFiles, 90);
  EXPECT_EQ(hashAfter(*baked, 90), hash);
  // The sequence changes in time: frozen at its first frame, the state is another.
  const auto frozen = buildSystem(
      loadFile(swirl("bake = { kind = \"curl-noise\", seed = 4, frequency = 2.0, evolution = 3.0, "
                     "voxel_size = 0.125 }\n")),
      1);
  EXPECT_NE(hashAfter(*frozen, 90), hash);
}

TEST_F(ioVectorField, AFileThatDoesNotLoadIsABuildErrorAtTheForcesKey) {
  const auto buildError = [&](const std::string& text) {
    try {
      buildSystem(loadFile(text));
    } catch (const BuildError& e) {
      EXPECT_EQ(e.what(), e.diagnostic().format());
      return e.diagnostic().format();
    }
    return std::string("no error");
  };
  EXPECT_EQ(buildError(fieldEffect("mode = \"drag\"\nfile = \"fields/none.vdb\"\n")),
            path("fx.toml") + ":9:8: error: forces.0.file: " + path("fields/none.vdb") +
                ": grid 'vel': no such file");
  bakeField(AnalyticField::uniform({1.0, 0.0, 0.0}), BakeSettings{}, path("fields/u.vdb"));
  EXPECT_EQ(buildError(fieldEffect("file = \"fields/u.vdb\"\ngrid = \"density\"\n")),
            path("fx.toml") + ":8:8: error: forces.0.file: " + path("fields/u.vdb") +
                ": grid 'density': no such grid (the file has: vel)");
  // Overridden to a file that is not there: the override is named.
  EXPECT_EQ(buildError(fieldEffect("file = \"fields/u.vdb\"\n")), "no error");
  try {
    buildSystem(loadFile(fieldEffect("file = \"fields/u.vdb\"\n"), {"forces.0.file=gone.vdb"}));
    ADD_FAILURE() << "no error";
  } catch (const BuildError& e) {
    EXPECT_EQ(e.diagnostic().format(), "--set forces.0.file: error: forces.0.file: " +
                                           path("gone.vdb") + ": grid 'vel': no such file");
  }
}

TEST(ioVectorFieldBuild, AdvectionAloneFollowsTheField) {
  // One particle at (1, 0, 0) advected by a rigid vortex of 1 rad/s about y for a quarter turn
  // with RK4: it reaches (0, 0, −1) (u = ω·ŷ × x turns +x toward −z), its radius kept.
  const std::string text =
      "format_version = 1\n[simulation]\nstep_rate = 120\nintegrator = \"rk4\"\n[[emitters]]\n"
      "position = [1.0, 0.0, 0.0]\nbursts = [{ time = 0.0, count = 1 }]\n[[forces]]\ntype = "
      "\"vector_field\"\nmode = \"advect\"\nbake = { kind = \"vortex\", voxel_size = 0.125, bounds "
      "= [-2, -1, -2, 2, 1, 2] }\n";
  const auto system = buildSystem(load(text));
  const int quarter = static_cast<int>(std::lround(120.0 * M_PI / 2.0));
  system->stepTicks(quarter);
  ASSERT_EQ(system->pool().size(), 1u);
  const Eigen::Vector3f x(system->pool().position().x[0], system->pool().position().y[0],
                          system->pool().position().z[0]);
  EXPECT_NEAR(x.x(), 0.0f, 5e-3f);
  EXPECT_NEAR(x.z(), -1.0f, 1e-4f);
  EXPECT_NEAR(x.norm(), 1.0f, 1e-4f);
}

// ---- the samples -------------------------------------------------------------------------------

EffectSettings loadSample(const std::string& name) {
  const LoadResult result =
      loadEffectFile(fs::path(TICKFX_SOURCE_DIR) / "samples" / (name + ".toml"));
  for (const Diagnostic& d : result.diagnostics) ADD_FAILURE() << d.format();
  return result.ok() ? *result.effect : EffectSettings{};
}

TEST(ioVectorFieldSamples, VortexSmokeSwirlsAboutTheAxisAndStaysInTheBox) {
  const auto system = buildSystem(loadSample("vortex_smoke"), 2);
  system->stepTicks(5 * 60);
  const ParticlePool& pool = system->pool();
  ASSERT_GT(pool.size(), 1000u);
  double spin = 0.0;  // mean angular velocity about y, of particles off the axis
  int counted = 0;
  for (Eigen::Index i = 0; i < static_cast<Eigen::Index>(pool.size()); ++i) {
    const double x = pool.position().x[i], y = pool.position().y[i], z = pool.position().z[i];
    const double r2 = x * x + z * z;
    // outside = "kill": every living particle is within the baked box (half a voxel of slack).
    EXPECT_LE(std::max(std::abs(x), std::abs(z)), 2.5) << i;
    EXPECT_GE(y, -0.1) << i;
    EXPECT_LE(y, 4.9) << i;
    if (r2 < 0.01) continue;
    // ω·ŷ × r = ω(z, 0, −x): ω = (z·vx − x·vz)/r².
    spin += (z * pool.velocity().x[i] - x * pool.velocity().z[i]) / r2;
    ++counted;
  }
  spin /= counted;
  // The smoke follows the air's 1.2 rad/s closely (k = 8 1/s), lagging a little as it drifts out.
  EXPECT_GT(spin, 1.0);
  EXPECT_LT(spin, 1.2);
  EXPECT_GT(pool.velocity().y.head(static_cast<Eigen::Index>(pool.size())).mean(), 0.3f)
      << "the smoke rises";
}

TEST(ioVectorFieldSamples, LeavesFallAndAreCarriedAboutByTheEvolvingWind) {
  const auto system = buildSystem(loadSample("leaves"), 2);
  system->stepTicks(5 * 60);
  const ParticlePool& pool = system->pool();
  const auto n = static_cast<Eigen::Index>(pool.size());
  ASSERT_GT(n, 100);
  EXPECT_LT(pool.velocity().y.head(n).mean(), -1.0f) << "the leaves fall";
  // Born at rest in a 5 m box, they are blown out of it, and move with different gusts.
  float widest = 0.0f;
  for (Eigen::Index i = 0; i < n; ++i) {
    widest = std::max({widest, std::abs(pool.position().x[i]), std::abs(pool.position().z[i])});
  }
  EXPECT_GT(widest, 3.5f);
  const Eigen::ArrayXf vx = pool.velocity().x.head(n);
  EXPECT_GT(std::sqrt((vx - vx.mean()).square().mean()), 0.3f);
  // The wind changes in time: the same leaves under the field frozen at its first frame go
  // elsewhere.
  EffectSettings frozen = loadSample("leaves");
  std::get<VectorFieldSettings>(frozen.forces[1]).fps = 0.0;
  const auto still = buildSystem(frozen, 2);
  still->stepTicks(5 * 60);
  EXPECT_NE(hashToHex(stateHash(still->pool())), hashToHex(stateHash(pool)));
}

}  // namespace
}  // namespace tickfx::io
