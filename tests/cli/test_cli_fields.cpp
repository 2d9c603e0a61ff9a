// Vector fields through the `tickfx` command line: `bake-field` writes every kind as the analytic
// field (read back with VectorField), refuses bad arguments with exact messages and writes
// nothing then; `run` and `check` with effects whose field files are missing, lack the grid, hold
// the wrong type or are truncated (exit 2 and nothing written for run, a warning for check).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "CliTestSupport.h"
#include "VdbTestData.h"
#include "fields/vdb/AnalyticField.h"
#include "fields/vdb/VectorField.h"

namespace fs = std::filesystem;

namespace tickfx {
namespace {

using cli_test::readAll;

std::string firstLine(const std::string& text) { return text.substr(0, text.find('\n')); }
using cli_test::Result;

class CliFields : public cli_test::CliFixture {
 protected:
  CliFields() : CliFixture("tickfx_cli_fields") {}
  void SetUp() override {
    CliFixture::SetUp();
    std::filesystem::create_directories(dir_ / "work");
  }

  // `tickfx ARGS` from the source tree, stdin closed; its output goes beside dir_/work, which
  // tests keep for the files the command writes.
  Result run(const std::string& args) const { return runProgram(TICKFX_CLI, args); }
  std::string path(const std::string& name) const { return (dir_ / "work" / name).string(); }
  std::string writeFile(const std::string& name, const std::string& text) const {
    std::ofstream(dir_ / "work" / name) << text;
    return path(name);
  }
  bool workIsEmpty() const { return fs::is_empty(dir_ / "work"); }
  // "HASH@TICKS" from the two lines --hash prints.
  static std::string hashOf(const Result& r) {
    const std::size_t at = r.out.find("state-hash: ");
    if (at == std::string::npos) return "no hash in: " + r.out + r.err;
    return r.out.substr(at + 12, 16);
  }
};

// Every voxel centre of the default box (±1 m) at 0.125 m, exact in float, holds the field there
// rounded to float once.
void expectVoxelCentres(const VectorField& field, const AnalyticField& exact, double time = 0.0) {
  int checked = 0;
  for (int i = -8; i <= 8; ++i) {
    for (int j = -8; j <= 8; ++j) {
      for (int k = -8; k <= 8; ++k) {
        const Eigen::Vector3f x(0.125f * i, 0.125f * j, 0.125f * k);
        const Eigen::Vector3f expected = exact.at(x.cast<double>(), time).cast<float>();
        ASSERT_EQ(field.sample(x, time), expected) << "at " << x.transpose() << ", t = " << time;
        ++checked;
      }
    }
  }
  EXPECT_EQ(checked, 17 * 17 * 17);
}

VectorField::Settings fileSettings(const std::string& file, const std::string& grid = "vel") {
  VectorField::Settings s;
  s.file = file;
  s.grid = grid;
  return s;
}

// ---- bake-field -------------------------------------------------------------------------------

TEST_F(CliFields, BakeFieldWritesEveryKindAsTheAnalyticField) {
  struct Case {
    std::string args;
    AnalyticField exact;
  };
  const std::vector<Case> cases = {
      {"uniform --velocity 1.5,-2,0.25", AnalyticField::uniform({1.5, -2.0, 0.25})},
      {"uniform", AnalyticField::uniform({1.0, 0.0, 0.0})},  // the documented defaults
      {"vortex --centre 0.1,0,-0.3 --axis 0,2,1 --omega -1.75",
       AnalyticField::vortex({0.1, 0.0, -0.3}, {0.0, 2.0, 1.0}, -1.75)},
      {"vortex", AnalyticField::vortex({0.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, 1.0)},
      {"shear --origin 0,0.5,0 --direction 0,0,1 --gradient 1,1,0 --rate 0.75",
       AnalyticField::shear({0.0, 0.5, 0.0}, {0.0, 0.0, 1.0}, {1.0, 1.0, 0.0}, 0.75)},
      {"shear", AnalyticField::shear({0.0, 0.0, 0.0}, {1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, 1.0)},
      {"curl-noise --seed 17 --frequency 2.5 --amplitude 0.8 --octaves 3",
       AnalyticField::curlNoise(17, 2.5, 0.8, 3)},
      {"curl-noise", AnalyticField::curlNoise(0, 3.0, 1.0, 4)}};
  int n = 0;
  for (const Case& c : cases) {
    SCOPED_TRACE(c.args);
    const std::string file = path("f" + std::to_string(n++) + ".vdb");
    const Result r = run("bake-field " + c.args + " --voxel-size 0.125 --out " + file);
    ASSERT_EQ(r.exit, 0) << r.err;
    EXPECT_EQ(r.err, "");
    const VectorField field(fileSettings(file));
    EXPECT_EQ(field.valueType(), "vec3s");
    EXPECT_FALSE(field.staggered());
    EXPECT_EQ(field.voxelSize(), 0.125);
    expectVoxelCentres(field, c.exact);
  }
}

TEST_F(CliFields, BakeFieldGridOptions) {
  const std::string file = path("v.vdb");
  const Result r = run(
      "bake-field vortex --omega 2 --grid velocity --bounds=-1,-0.5,-1,1,0.5,1 --voxel-size 0.25 "
      "--background 3,2,1 --staggered --out " +
      file);
  ASSERT_EQ(r.exit, 0) << r.err;
  EXPECT_EQ(r.out, file + ": vortex field, grid 'velocity', 405 voxels of 0.25 m\n");  // 9·5·9
  const VectorField field(fileSettings(file, "velocity"));
  EXPECT_TRUE(field.staggered());
  // A staggered grid of an affine field samples the field itself (to float rounding).
  const AnalyticField exact = AnalyticField::vortex({0.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, 2.0);
  for (const Eigen::Vector3f& x :
       {Eigen::Vector3f(0.3f, 0.1f, -0.4f), Eigen::Vector3f(-0.6f, 0.0f, 0.2f)}) {
    const Eigen::Vector3f expected = exact.at(x.cast<double>()).cast<float>();
    EXPECT_LT((field.sample(x) - expected).norm(), 1e-5f) << x.transpose();
  }
  // Outside the bounds: the background.
  EXPECT_EQ(field.sample(Eigen::Vector3f(0.0f, 3.0f, 0.0f)), Eigen::Vector3f(3.0f, 2.0f, 1.0f));
}

TEST_F(CliFields, BakeFieldWritesASequenceFrameByFrame) {
  const Result r =
      run("bake-field curl-noise --seed 5 --frequency 2 --evolution 3 --voxel-size 0.125 --frames "
          "3..5 --fps 4 --out " +
          path("seq/noise.{frame}.vdb"));
  ASSERT_EQ(r.exit, 0) << r.err;
  for (const char* name : {"seq/noise.0003.vdb", "seq/noise.0004.vdb", "seq/noise.0005.vdb"}) {
    EXPECT_TRUE(fs::exists(path(name))) << name;
  }
  EXPECT_FALSE(fs::exists(path("seq/noise.0002.vdb")));
  EXPECT_FALSE(fs::exists(path("seq/noise.0006.vdb")));
  EXPECT_NE(r.out.find(path("seq/noise.0005.vdb") +
                       ": curl-noise field, grid 'vel', 4913 voxels of 0.125 m, t = 0.5 s\n"),
            std::string::npos)
      << r.out;
  // Frame f holds the field at (f − 3)/4 s: read as a sequence, it is the evolving noise at each
  // frame's time.
  VectorField::Settings s = fileSettings(path("seq/noise.{frame}.vdb"));
  s.fps = 4.0;
  s.firstFrame = 3;
  s.lastFrame = 5;
  const VectorField field(s);
  EXPECT_EQ(field.frameCount(), 3);
  const AnalyticField exact = AnalyticField::curlNoise(5, 2.0, 1.0, 4, 3.0);
  for (const double t : {0.0, 0.25, 0.5}) expectVoxelCentres(field, exact, t);
  // Other paddings and negative frames, named as a sequence of an effect reads them.
  ASSERT_EQ(run("bake-field uniform --frames -1..1 --fps 24 --frame-padding 2 --out " +
                path("u_{frame}.vdb"))
                .exit,
            0);
  for (const char* name : {"u_-01.vdb", "u_00.vdb", "u_01.vdb"}) {
    EXPECT_TRUE(fs::exists(path(name))) << name;
  }
}

TEST_F(CliFields, BakeFieldUsageErrorsExitTwoAndWriteNothing) {
  struct Case {
    std::string args, message;
  };
  const std::string out = " --out " + path("x.vdb");
  const std::vector<Case> cases = {
      {"",
       "tickfx bake-field: expected a field kind: tickfx bake-field KIND --out FILE.vdb (KIND: "
       "uniform, vortex, shear or curl-noise)"},
      {"vortex", "tickfx bake-field: --out FILE.vdb is required"},
      {"vortx" + out, "tickfx bake-field: unknown kind 'vortx' (did you mean 'vortex'?)"},
      {"smoke" + out,
       "tickfx bake-field: unknown kind 'smoke' (expected uniform, vortex, shear or curl-noise)"},
      {"vortex extra" + out,
       "tickfx bake-field: expected a field kind: tickfx bake-field KIND --out FILE.vdb (KIND: "
       "uniform, vortex, shear or curl-noise), got extra arguments"},
      {"vortex --spin 2" + out,
       "tickfx bake-field: unknown option '--spin' (see tickfx bake-field --help)"},
      {"uniform --omega 2" + out,
       "tickfx bake-field: --omega does not apply to kind 'uniform' (its options: --velocity)"},
      {"shear --seed 1" + out,
       "tickfx bake-field: --seed does not apply to kind 'shear' (its options: --origin, "
       "--direction, --gradient and --rate)"},
      {"vortex --axis 0,0,0" + out,
       "tickfx bake-field: --axis: '0,0,0' is not a direction (expected x,y,z not all zero)"},
      {"vortex --centre 1,2" + out, "tickfx bake-field: --centre: '1,2' is not 3 numbers x,y,z"},
      {"vortex --centre 1,2,x" + out,
       "tickfx bake-field: --centre: 'x' is not a number in [-1e+09, 1e+09]"},
      {"vortex --omega nan" + out,
       "tickfx bake-field: --omega: 'nan' is not a number in [-1e+09, 1e+09]"},
      {"curl-noise --frequency 0" + out,
       "tickfx bake-field: --frequency: '0' is not a number in (0, 1e+09]"},
      {"curl-noise --octaves 17" + out,
       "tickfx bake-field: --octaves: '17' is not a whole number in [1, 16]"},
      {"curl-noise --seed -3" + out,
       "tickfx bake-field: --seed: '-3' is not a whole number in [0, 9223372036854775807]"},
      {"uniform --voxel-size -0.1" + out,
       "tickfx bake-field: --voxel-size: '-0.1' is not a number in (0, 1e+09]"},
      {"uniform --bounds 0,0,0,1,1" + out,
       "tickfx bake-field: --bounds: '0,0,0,1,1' is not 6 numbers x0,y0,z0,x1,y1,z1"},
      {"uniform --bounds 0,0,1,1,1,0" + out,
       "tickfx bake-field: --bounds: z1 = 0 is below z0 = 1 (expected x0,y0,z0,x1,y1,z1 with x0 "
       "<= x1, y0 <= y1 and z0 <= z1)"},
      {"uniform --voxel-size 1 --bounds 0.1,0,0,0.9,1,1" + out,
       "tickfx bake-field: --bounds: the box holds no voxel centre at --voxel-size 1 (expected at "
       "least one point i*V on each axis)"},
      {"uniform --voxel-size 0.001" + out,
       "tickfx bake-field: --voxel-size 0.001 and --bounds make 8012006001 voxels a frame, "
       "8012006001 over 1 frame (expected at most 100000000)"},
      {"uniform --voxel-size 1e-9 --bounds 0,0,0,1e-9,1e-9,2" + out,
       "tickfx bake-field: --voxel-size: 1e-09 m puts the bounds 2000000000 voxels from the "
       "origin (expected at least 2e-09 m for these bounds)"},
      {"uniform --grid ''" + out, "tickfx bake-field: --grid: the grid needs a name"},
      {"uniform --frames 1..3" + out,
       "tickfx bake-field: --frames needs --fps (the sequence's frames per second)"},
      {"uniform --fps 24" + out, "tickfx bake-field: --fps needs --frames A..B"},
      {"uniform --frame-padding 2" + out, "tickfx bake-field: --frame-padding needs --frames A..B"},
      {"uniform --frames 1..3 --fps 24" + out,
       "tickfx bake-field: --out: '" + path("x.vdb") +
           "' has no {frame} (expected a pattern such as vel.{frame}.vdb with --frames)"},
      {"uniform --out " + path("x.{frame}.vdb"), "tickfx bake-field: --out: '" +
                                                     path("x.{frame}.vdb") +
                                                     "' has {frame} but no --frames A..B is given"},
      {"uniform --frames 3..1 --fps 24 --out " + path("x.{frame}.vdb"),
       "tickfx bake-field: --frames: '3..1' is not a frame range A..B (whole numbers from "
       "-1000000 to 1000000, A <= B)"},
      {"uniform --frames 1-3 --fps 24 --out " + path("x.{frame}.vdb"),
       "tickfx bake-field: --frames: '1-3' is not a frame range A..B (whole numbers from -1000000 "
       "to 1000000, A <= B)"},
      {"uniform --frames 0..10000 --fps 24 --out " + path("x.{frame}.vdb"),
       "tickfx bake-field: --frames: 10001 frames are too many (expected at most 10000)"},
      {"uniform --frames 0..1 --fps 0 --out " + path("x.{frame}.vdb"),
       "tickfx bake-field: --fps: '0' is not a number in (0, 1e+06]"},
      // Too many voxels only over all the frames of a sequence.
      {"uniform --voxel-size 0.02 --frames 1..100 --fps 24 --out " + path("d/x.{frame}.vdb"),
       "tickfx bake-field: --voxel-size 0.02 and --bounds make 1030301 voxels a frame, 103030100 "
       "over 100 frames (expected at most 100000000)"},
  };
  for (const Case& c : cases) {
    const Result r = run("bake-field " + c.args);
    EXPECT_EQ(r.exit, 2) << c.args << "\n" << r.err;
    EXPECT_EQ(r.err, c.message + "\n") << c.args;
    EXPECT_EQ(r.out, "") << c.args;
    EXPECT_TRUE(workIsEmpty()) << c.args;
  }
}

TEST_F(CliFields, BakeFieldHelpAndFailures) {
  const Result help = run("bake-field --help");
  EXPECT_EQ(help.exit, 0);
  EXPECT_EQ(help.out.rfind("usage: tickfx bake-field KIND --out FILE.vdb", 0), 0u) << help.out;
  for (const char* documented : {"--velocity X,Y,Z   m/s [1,0,0]", "--omega W          rad/s [1]",
                                 "--frequency F      rad/m, > 0 [3]",
                                 "--voxel-size V       metres [0.1]", "--frames A..B"}) {
    EXPECT_NE(help.out.find(documented), std::string::npos) << documented;
  }
  EXPECT_NE(run("--help").out.find("bake-field KIND --out FILE.vdb"), std::string::npos);
  // A file that cannot be written is a failure at run time (exit 1), and leaves nothing.
  writeFile("occupied", "a file where a folder should go");
  const Result r = run("bake-field uniform --out " + path("occupied/u.vdb"));
  EXPECT_EQ(r.exit, 1) << r.err;
  EXPECT_EQ(r.err.rfind("tickfx bake-field: error: ", 0), 0u) << r.err;
  EXPECT_FALSE(fs::exists(path("occupied/u.vdb.partial")));
}

// ---- run and check with vector fields ---------------------------------------------------------

// An effect of a few particles in a box pulled toward the field `source` (TOML keys of the force).
std::string fieldEffect(const std::string& source) {
  return "format_version = 1\n"
         "[simulation]\n"
         "step_rate = 60\n"
         "[[emitters]]\n"
         "shape = \"box\"\n"
         "rate = 200.0\n"
         "[[forces]]\n"
         "type = \"vector_field\"\n"
         "mode = \"drag\"\n" +
         source;
}

TEST_F(CliFields, RunFollowsAFieldBakedByTheCommandLine) {
  // The effect names its field relative to its own directory, and runs from another one.
  fs::create_directories(path("shot/fields"));
  ASSERT_EQ(
      run("bake-field vortex --omega 2 --voxel-size 0.125 --out " + path("shot/fields/vortex.vdb"))
          .exit,
      0);
  const std::string effect =
      writeFile("shot/fx.toml", fieldEffect("file = \"fields/vortex.vdb\"\noutside = \"kill\"\n"));
  const Result file = run("check " + effect);
  EXPECT_EQ(file.exit, 0);
  EXPECT_EQ(file.err, "");
  const std::string args = " --seconds 1 --format none --hash";
  const Result fromFile = run("run " + effect + args);
  ASSERT_EQ(fromFile.exit, 0) << fromFile.err;
  // The same vortex as a bake table: the same bits.
  const std::string baked = writeFile(
      "baked.toml",
      fieldEffect("bake = { kind = \"vortex\", omega = 2.0, voxel_size = 0.125 }\noutside = "
                  "\"kill\"\n"));
  EXPECT_EQ(hashOf(run("run " + baked + args)), hashOf(fromFile));
  // --set reaches the field's keys: a faster vortex is another state.
  const Result faster = run("run " + baked + args + " --set forces.0.bake.omega=3");
  ASSERT_EQ(faster.exit, 0) << faster.err;
  EXPECT_NE(hashOf(faster), hashOf(fromFile));
  EXPECT_EQ(hashOf(run("run " + effect + args + " --set forces.0.scale=1")), hashOf(fromFile));
}

TEST_F(CliFields, FieldFilesThatDoNotLoadStopRunAndWarnInCheck) {
  fs::create_directories(path("fields"));
  ASSERT_EQ(run("bake-field curl-noise --voxel-size 0.125 --out " + path("fields/noise.vdb")).exit,
            0);
  // A grid of floats where a vector grid is expected.
  vdb_test::GridFileSpec scalar;
  scalar.name = "vel";
  scalar.type = vdb_test::GridType::Float;
  scalar.activeVoxels = {{{0, 0, 0}, {1.0}}};
  vdb_test::writeGridFile(path("fields/scalar.vdb"), scalar);
  // A file cut inside its grid data.
  const std::string noise = readAll(path("fields/noise.vdb"));
  std::ofstream(path("fields/cut.vdb"), std::ios::binary) << noise.substr(0, noise.size() / 2);

  struct Case {
    std::string name, keys, file, grid, what;
  };
  const std::vector<Case> cases = {
      {"missing_file", "file = \"fields/none.vdb\"\n", "fields/none.vdb", "vel", "no such file"},
      {"missing_grid", "file = \"fields/noise.vdb\"\ngrid = \"v\"\n", "fields/noise.vdb", "v",
       "no such grid (the file has: vel)"},
      {"wrong_type", "file = \"fields/scalar.vdb\"\n", "fields/scalar.vdb", "vel",
       "holds float values (Tree_float_5_4_3); a vector field needs vec3s or vec3d"},
      {"truncated", "file = \"fields/cut.vdb\"\n", "fields/cut.vdb", "vel",
       "cannot read the grid (the file is truncated: a grid ends at byte " +
           std::to_string(noise.size()) + " of " + std::to_string(noise.size() / 2) + ")"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const std::string effect = writeFile(c.name + ".toml", fieldEffect(c.keys));
    const std::string message =
        ":10:8: error: forces.0.file: " + path(c.file) + ": grid '" + c.grid + "': " + c.what;
    const Result r = run("run " + effect + " --format csv --out " + path("never"));
    EXPECT_EQ(r.exit, 2) << r.err;
    EXPECT_EQ(r.err, effect + message + "\n");
    EXPECT_EQ(r.out, "");
    EXPECT_FALSE(fs::exists(path("never")));
    // check warns, with the fix, and does not fail.
    const Result check = run("check " + effect);
    EXPECT_EQ(check.exit, 0) << check.err;
    EXPECT_EQ(check.err, effect + ":10:8: warning: forces.0.file: " + path(c.file) + ": grid '" +
                             c.grid + "': " + c.what +
                             " (tickfx run stops at this: write the file first, e.g. with tickfx "
                             "bake-field, or correct file and grid)\n");
    // determinism stops the same way.
    const Result d = run("determinism " + effect + " --seconds 0.1");
    EXPECT_EQ(d.exit, 2);
    EXPECT_EQ(firstLine(d.err), effect + message);
  }
}

TEST_F(CliFields, CheckWarnsWhenAStepCrossesMoreThanAVoxel) {
  const std::string effect = writeFile(
      "fast.toml", fieldEffect("scale = 4.0\nbake = { kind = \"uniform\", velocity = [0, 0, 9], "
                               "voxel_size = 0.125 }\n"));
  const Result r = run("check " + effect);
  EXPECT_EQ(r.exit, 0);
  EXPECT_EQ(r.err, effect +
                       ":7:1: warning: forces.0: the field carries particles up to 9 m/s, 9·dt = "
                       "0.15 m a step, more than a voxel (0.125 m) (use a step_rate of at least 72 "
                       "Hz)\n");
  const Result fixed = run("check " + effect + " --set simulation.step_rate=72");
  EXPECT_EQ(fixed.err, "");
  EXPECT_NE(fixed.out.find("ok, 0 warning(s)"), std::string::npos);
  // run prints the warning once, after building, and runs.
  const Result ran = run("run " + effect + " --seconds 0.5 --format none --quiet");
  EXPECT_EQ(ran.exit, 0);
  EXPECT_EQ(ran.err, r.err);
}

}  // namespace
}  // namespace tickfx
