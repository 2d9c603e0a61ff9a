// Effect-file validation: every bad file is checked for its exact messages, lines and columns.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "io/effect/EffectParser.h"

namespace tickfx::io {
namespace {

// Every diagnostic of `text` (read as "bad.toml"), formatted.
std::vector<std::string> messages(std::string_view text,
                                  const std::vector<std::string>& overrides = {}) {
  const LoadResult result = parseEffect(text, "bad.toml", overrides);
  std::vector<std::string> out;
  for (const Diagnostic& d : result.diagnostics) out.push_back(d.format());
  if (!out.empty()) {
    EXPECT_FALSE(result.ok()) << "errors but an effect";
  }
  return out;
}

using Lines = std::vector<std::string>;

// ---- bad files --------------------------------------------------------------------------------

TEST(ioParse, EmptyFileMissesEveryRequiredPart) {
  EXPECT_EQ(
      messages(""),
      (Lines{"bad.toml:1:1: error: format_version: missing (expected format_version = 1)",
             "bad.toml:1:1: error: simulation: missing (expected a [simulation] table with at "
             "least step_rate)",
             "bad.toml:1:1: error: emitters: missing (expected at least one [[emitters]] table)"}));
  // Comments and blank lines only: the same.
  EXPECT_EQ(messages("# nothing yet\n\n").size(), 3u);
}

TEST(ioParse, MalformedTomlGivesTheParserPosition) {
  EXPECT_EQ(
      messages("format_version = 1\n[simulation\nstep_rate = 60\n"),
      (Lines{"bad.toml:2:12: error: Error while parsing table header: expected ']', saw '\\n'"}));
  EXPECT_EQ(
      messages("format_version = 1\n[simulation]\nstep_rate = 60 60\n"),
      (Lines{"bad.toml:3:16: error: Error while parsing key-value pair: expected a comment or "
             "whitespace, saw '6'"}));
  EXPECT_EQ(messages("format_version = 1\n[simulation]\nstep_rate = 60\nstep_rate = 61\n"),
            (Lines{"bad.toml:4:13: error: Error while parsing key-value pair: cannot redefine "
                   "existing integer 'step_rate'"}));
  // An integer too large for TOML's 64 bits is the parser's to report.
  EXPECT_EQ(messages("format_version = 1\n[simulation]\nseed = 99999999999999999999\n"),
            (Lines{"bad.toml:3:28: error: Error while parsing decimal integer: "
                   "'99999999999999999999' is not representable in 64 bits"}));
}

TEST(ioParse, ZeroStepRate) {
  EXPECT_EQ(messages(R"(format_version = 1
[simulation]
step_rate = 0
[[emitters]]
rate = 10
)"),
            (Lines{"bad.toml:3:13: error: simulation.step_rate: 0 is out of range (expected ticks "
                   "per second (Hz), an integer from 1 to 1000000)"}));
}

TEST(ioParse, WrongTypes) {
  EXPECT_EQ(
      messages(R"(format_version = 1
[simulation]
step_rate = "60"
seed = 1.0
max_particles = 1e5
threads = true
[[emitters]]
rate = "fast"
position = "origin"
shape = 3
surface = "yes"
name = ""
)"),
      (Lines{
          "bad.toml:3:13: error: simulation.step_rate: got a string \"60\" (expected ticks per "
          "second (Hz), an integer from 1 to 1000000)",
          "bad.toml:4:8: error: simulation.seed: 1.0 is not an integer (expected an integer "
          "from 0 to 9223372036854775807)",
          "bad.toml:5:17: error: simulation.max_particles: 100000.0 is not an integer "
          "(expected an integer from 1 to 1000000000)",
          "bad.toml:6:11: error: simulation.threads: got true (expected worker threads, an "
          "integer from 0 (all cores) to 1024)",
          "bad.toml:8:8: error: emitters.0.rate: got a string \"fast\" (expected particles per "
          "second, a number from 0 to 1e9)",
          "bad.toml:9:12: error: emitters.0.position: got a string \"origin\" (expected [x, y, "
          "z] in metres, each from -1e9 to 1e9)",
          "bad.toml:10:9: error: emitters.0.shape: got the integer 3 (expected shape, one of: "
          "point, sphere, box, disc)",
          // The shape could not be read, so its parameters are not judged.
          "bad.toml:12:8: error: emitters.0.name: got an empty string (expected a name: a "
          "non-empty string, unique among the emitters)",
      }));
}

TEST(ioParse, MissingRequiredKeysPointAtTheirTable) {
  EXPECT_EQ(
      messages(R"(format_version = 1
[simulation]
integrator = "rk4"

[[emitters]]
bursts = [{ time = 1.0 }]

[[forces]]
k = 0.5

[[forces]]
type = "drag"
)"),
      (Lines{"bad.toml:2:1: error: simulation.step_rate: missing (expected ticks per second "
             "(Hz), an integer from 1 to 1000000)",
             "bad.toml:6:11: error: emitters.0.bursts.0.count: missing (expected particles, an "
             "integer from 1 to simulation.max_particles = 1000000)",
             "bad.toml:8:1: error: forces.0.type: missing (expected force type, one of: "
             "gravity, drag, wind, anchor_spring, vector_field)",
             "bad.toml:11:1: error: forces.1.k: missing (expected a rate in 1/s, a number from "
             "0 to 1e9)"}));
}

TEST(ioParse, UnknownKeyWithSuggestion) {
  // [simulaton] and [simulation] in one file: both tables exist, the misspelt one is unknown.
  EXPECT_EQ(
      messages(R"(format_version = 1
[simulaton]
step_rate = 60
[simulation]
step_rate = 60
integratr = "rk4"
[[emitters]]
rate = 10
lifetme = 2.0
)"),
      (Lines{"bad.toml:2:2: error: simulaton: unknown key \"simulaton\" (did you mean "
             "\"simulation\"?)",
             "bad.toml:6:1: error: simulation.integratr: unknown key \"integratr\" (did you mean "
             "\"integrator\"?)",
             "bad.toml:9:1: error: emitters.0.lifetme: unknown key \"lifetme\" (did you mean "
             "\"lifetime\"?)"}));
}

TEST(ioParse, UnknownKeyWithoutSuggestionListsTheKeys) {
  EXPECT_EQ(
      messages(R"(format_version = 1
[simulation]
step_rate = 60
colour = "red"
[[emitters]]
rate = 10
)"),
      (Lines{"bad.toml:4:1: error: simulation.colour: unknown key \"colour\" (expected one of: "
             "step_rate, integrator, seed, max_particles, max_ticks_per_frame, overrun, "
             "threads, nonfinite)"}));
}

TEST(ioParse, MisspeltIntegratorShapeAndForceType) {
  EXPECT_EQ(
      messages(R"(format_version = 1
[simulation]
step_rate = 60
integrator = "velocity_verlett"
overrun = "fallbehind"
nonfinite = "kil"
[[emitters]]
shape = "sphre"
[[forces]]
type = "gravty"
[[forces]]
type = "magnet"
)"),
      (Lines{"bad.toml:4:14: error: simulation.integrator: unknown integrator "
             "\"velocity_verlett\" (did you mean \"velocity_verlet\"?)",
             "bad.toml:5:11: error: simulation.overrun: unknown overrun policy \"fallbehind\" "
             "(did you mean \"fall_behind\"?)",
             "bad.toml:6:13: error: simulation.nonfinite: unknown nonfinite policy \"kil\" (did "
             "you mean \"kill\"?)",
             "bad.toml:8:9: error: emitters.0.shape: unknown shape \"sphre\" (did you mean "
             "\"sphere\"?)",
             "bad.toml:10:8: error: forces.0.type: unknown force type \"gravty\" (did you mean "
             "\"gravity\"?)",
             "bad.toml:12:8: error: forces.1.type: unknown force type \"magnet\" (expected one "
             "of: gravity, drag, wind, anchor_spring, vector_field)"}));
  // Case is not a spelling: "RK4" is one edit-free step from "rk4" but still wrong.
  EXPECT_EQ(
      messages("format_version = 1\n[simulation]\nstep_rate = 60\nintegrator = \"RK4\"\n"
               "[[emitters]]\n"),
      (Lines{"bad.toml:4:14: error: simulation.integrator: unknown integrator \"RK4\" (did you "
             "mean \"rk4\"?)"}));
}

TEST(ioParse, NegativeAndZeroQuantities) {
  EXPECT_EQ(
      messages(R"(format_version = 1
[simulation]
step_rate = -60
[[emitters]]
rate = -5
speed = -1.5
mass = 0
lifetime = 0.0
[[forces]]
type = "drag"
k = -0.1
[[forces]]
type = "anchor_spring"
stiffness = 0
damping = -1
)"),
      (Lines{"bad.toml:3:13: error: simulation.step_rate: -60 is out of range (expected ticks "
             "per second (Hz), an integer from 1 to 1000000)",
             "bad.toml:5:8: error: emitters.0.rate: -5 is out of range (expected particles per "
             "second, a number from 0 to 1e9)",
             "bad.toml:6:9: error: emitters.0.speed: -1.5 is out of range (expected metres per "
             "second, a number from 0 to 1e9)",
             "bad.toml:7:8: error: emitters.0.mass: 0 is out of range (expected kilograms, a "
             "number > 0 and <= 1e9)",
             "bad.toml:8:12: error: emitters.0.lifetime: 0 is out of range (expected seconds, a "
             "number > 0 and <= 1e9)",
             "bad.toml:11:5: error: forces.0.k: -0.1 is out of range (expected a rate in 1/s, a "
             "number from 0 to 1e9)",
             "bad.toml:14:13: error: forces.1.stiffness: 0 is out of range (expected N/m, a "
             "number > 0 and <= 1e9)",
             "bad.toml:15:11: error: forces.1.damping: -1 is out of range (expected N·s/m, a "
             "number from 0 to 1e9)"}));
}

TEST(ioParse, NanAndInfinityAreRejected) {
  EXPECT_EQ(
      messages(R"(format_version = 1
[simulation]
step_rate = 60
[[emitters]]
rate = nan
lifetime = inf
position = [0.0, -inf, 0.0]
[[forces]]
type = "wind"
amplitude = 1.0
frequency = nan
phase = -nan
)"),
      (Lines{"bad.toml:5:8: error: emitters.0.rate: nan is not a finite number (expected "
             "particles per second, a number from 0 to 1e9)",
             "bad.toml:6:12: error: emitters.0.lifetime: inf is not a finite number (expected "
             "seconds, a number > 0 and <= 1e9)",
             "bad.toml:7:18: error: emitters.0.position.1: -inf is not a finite number "
             "(expected [x, y, z] in metres, each from -1e9 to 1e9)",
             "bad.toml:11:13: error: forces.0.frequency: nan is not a finite number (expected "
             "hertz, a number from 0 to 1000000)",
             "bad.toml:12:9: error: forces.0.phase: nan is not a finite number (expected "
             "radians, a number from -1e9 to 1e9)"}));
}

TEST(ioParse, AbsurdCountsAreRejected) {
  EXPECT_EQ(
      messages(R"(format_version = 1
[simulation]
step_rate = 60
max_particles = 2000000000
max_ticks_per_frame = 0
[[emitters]]
rate = 2e9
[[emitters]]
bursts = [{ time = 0.0, count = 1000001 }, { time = 1.0, count = 0 }]
)"),
      (Lines{"bad.toml:4:17: error: simulation.max_particles: 2000000000 is out of range "
             "(expected an integer from 1 to 1000000000)",
             "bad.toml:5:23: error: simulation.max_ticks_per_frame: 0 is out of range (expected "
             "an integer from 1 to 100000)",
             "bad.toml:7:8: error: emitters.0.rate: 2000000000 is out of range (expected "
             "particles per second, a number from 0 to 1e9)",
             // max_particles was refused, so bursts are held to its default.
             "bad.toml:9:33: error: emitters.1.bursts.0.count: 1000001 is out of range "
             "(expected particles, an integer from 1 to simulation.max_particles = 1000000)",
             "bad.toml:9:66: error: emitters.1.bursts.1.count: 0 is out of range (expected "
             "particles, an integer from 1 to simulation.max_particles = 1000000)"}));
  // A burst larger than the file's own max_particles.
  EXPECT_EQ(messages(R"(format_version = 1
[simulation]
step_rate = 60
max_particles = 500
[[emitters]]
bursts = [{ time = 0.0, count = 501 }]
)"),
            (Lines{"bad.toml:6:33: error: emitters.0.bursts.0.count: 501 is out of range (expected "
                   "particles, an integer from 1 to simulation.max_particles = 500)"}));
}

TEST(ioParse, ParametersOfAnotherShapeOrForceType) {
  EXPECT_EQ(
      messages(R"(format_version = 1
[simulation]
step_rate = 60
[[emitters]]
shape = "sphere"
size = [1, 1, 1]
[[emitters]]
normal = [0, 0, 1]
[[forces]]
type = "gravity"
k = 0.3
)"),
      (Lines{"bad.toml:6:1: error: emitters.0.size: does not apply to shape \"sphere\" "
             "(expected for a sphere: radius, surface)",
             "bad.toml:8:1: error: emitters.1.normal: does not apply to shape \"point\" "
             "(expected no parameters for a point)",
             "bad.toml:11:1: error: forces.0.k: does not apply to a force of type \"gravity\" "
             "(expected for gravity: type, acceleration)"}));
}

TEST(ioParse, FractionsAndAnglesOutOfRange) {
  EXPECT_EQ(
      messages(R"(format_version = 1
[simulation]
step_rate = 60
[[emitters]]
speed_jitter = 1.5
lifetime_jitter = 1
spread = 200
start = 2.0
stop = 1.0
)"),
      (Lines{"bad.toml:5:16: error: emitters.0.speed_jitter: 1.5 is out of range (expected a "
             "fraction from 0 to 1)",
             "bad.toml:6:19: error: emitters.0.lifetime_jitter: 1 is out of range (expected a "
             "fraction >= 0 and < 1)",
             "bad.toml:7:10: error: emitters.0.spread: 200 is out of range (expected degrees, a "
             "number from 0 to 180)",
             "bad.toml:9:8: error: emitters.0.stop: 1 is before start = 2 (expected seconds, a "
             "number from start to 1e9)"}));
}

TEST(ioParse, VectorsOfTheWrongShape) {
  EXPECT_EQ(
      messages(R"(format_version = 1
[simulation]
step_rate = 60
[[emitters]]
position = [1.0, 2.0]
direction = [0, 0, 0]
shape = "box"
size = [1.0, "2", -3.0]
[[forces]]
type = "wind"
direction = [0.0, 0.0, 0.0]
amplitude = 1.0
frequency = 2.0
)"),
      (Lines{"bad.toml:5:12: error: emitters.0.position: got 2 entries (expected [x, y, z] in "
             "metres, each from -1e9 to 1e9)",
             "bad.toml:6:13: error: emitters.0.direction: got [0, 0, 0] (expected a direction "
             "[x, y, z], each from -1e9 to 1e9, not all zero)",
             "bad.toml:8:14: error: emitters.0.size.1: got a string \"2\" (expected [x, y, z] "
             "edge lengths in metres, each from 0 to 1e9)",
             "bad.toml:8:19: error: emitters.0.size.2: -3 is out of range (expected [x, y, z] "
             "edge lengths in metres, each from 0 to 1e9)",
             "bad.toml:11:13: error: forces.0.direction: got [0, 0, 0] (expected a direction "
             "[x, y, z], each from -1e9 to 1e9, not all zero)"}));
}

// Conditions only the core types enforced used to pass the parser, and `tickfx run` then stopped
// with exit 1 and no position ("emitter direction must not be zero"). Each type's validate() is
// now asked at load, and its problems are shown where the value is written.
TEST(ioParse, DirectionsMustNormaliseInThePrecisionTheyAreUsedIn) {
  // An emitter's direction is normalised in double: |v|² = 2e-400 is zero there.
  EXPECT_EQ(messages(R"(format_version = 1
[simulation]
step_rate = 60
[[emitters]]
direction = [1e-200, 1e-200, 0]
)"),
            (Lines{"bad.toml:5:13: error: emitters.0.direction: is too short to normalise in "
                   "double precision (expected a direction [x, y, z] at least 1.5e-154 long)"}));
  // Likewise a disc's normal.
  EXPECT_EQ(messages(R"(format_version = 1
[simulation]
step_rate = 60
[[emitters]]
shape = "disc"
normal = [0, -1e-160, 0]
)"),
            (Lines{"bad.toml:6:10: error: emitters.0.normal: is too short to normalise in double "
                   "precision (expected a direction [x, y, z] at least 1.5e-154 long)"}));
  // A wind's direction is rounded to float and normalised there: 1e-50 is 0 in float, and 1e-20
  // would leave a squared length below the smallest normal float.
  const std::string wind = R"(format_version = 1
[simulation]
step_rate = 60
[[emitters]]
bursts = [{ time = 0.0, count = 1 }]
[[forces]]
type = "wind"
amplitude = 1.0
frequency = 1.0
direction = [1e-50, 0, 0]
)";
  const std::string windError =
      "error: forces.0.direction: is too short to normalise in float precision (expected a "
      "direction [x, y, z] at least 1.1e-19 long)";
  EXPECT_EQ(messages(wind), (Lines{"bad.toml:10:13: " + windError}));
  EXPECT_EQ(messages(wind, {"forces.0.direction=[0, 1e-20, 0]"}),
            (Lines{"--set forces.0.direction: " + windError}));
  // The lengths the messages give pass.
  EXPECT_TRUE(messages(wind, {"forces.0.direction=[0, 1.1e-19, 0]"}).empty());
  EXPECT_TRUE(messages(R"(format_version = 1
[simulation]
step_rate = 60
[[emitters]]
shape = "disc"
normal = [0, 0, -1.5e-154]
direction = [1.5e-154, 0, 0]
)")
                  .empty());
  // A value the parser already refused is reported once, in the parser's words; the entry's
  // other values are judged by the core once the entry reads without errors.
  EXPECT_EQ(messages(R"(format_version = 1
[simulation]
step_rate = 60
[[emitters]]
direction = [0, 0, 0]
shape = "disc"
normal = [1e-200, 0, 0]
)"),
            (Lines{"bad.toml:5:13: error: emitters.0.direction: got [0, 0, 0] (expected a "
                   "direction [x, y, z], each from -1e9 to 1e9, not all zero)"}));
}

TEST(ioParse, OutputErrors) {
  EXPECT_EQ(
      messages(R"(format_version = 1
[simulation]
step_rate = 60
[[emitters]]
[output]
fps = "30000/0"
seconds = 4.0
frames = 100
formats = ["csv", "CSV", "ply", "ply"]
directory = ""
)"),
      (Lines{"bad.toml:6:7: error: output.fps: \"30000/0\" is out of range (expected frames "
             "per second, an integer from 1 to 1000000 or a ratio string like \"30000/1001\")",
             "bad.toml:8:10: error: output.frames: given together with output.seconds "
             "(expected either seconds or frames)",
             "bad.toml:9:19: error: output.formats.1: unknown cache format \"CSV\" (did you mean "
             "\"csv\"?)",
             "bad.toml:9:33: error: output.formats.3: \"ply\" is listed twice (expected each "
             "format at most once)",
             "bad.toml:10:13: error: output.directory: got an empty string (expected a directory "
             "path, a non-empty string)"}));
  // 11 fps: a frame of 705600000/11 flicks is not whole, so frame times would drift.
  EXPECT_EQ(
      messages("format_version = 1\n[simulation]\nstep_rate = 60\n[[emitters]]\n[output]\n"
               "fps = 11\nformats = \"csv\"\n"),
      (Lines{"bad.toml:6:7: error: output.fps: 11 frames per second do not last a whole number "
             "of flicks (expected a rate whose frame is a whole number of 1/705600000 s, such "
             "as 24, 25, 30, 60, 120 or \"30000/1001\")",
             "bad.toml:7:11: error: output.formats: got a string \"csv\" (expected an array of "
             "cache formats, such as [\"csv\", \"ply\"])"}));
  EXPECT_EQ(
      messages("format_version = 1\n[simulation]\nstep_rate = 60\n[[emitters]]\n[output]\n"
               "vdb_compression = \"zip\"\nvdb_positions = \"Fixed16\"\n"),
      (Lines{"bad.toml:6:19: error: output.vdb_compression: unknown VDB compression \"zip\" "
             "(expected one of: none, blosc)",
             "bad.toml:7:17: error: output.vdb_positions: unknown VDB positions \"Fixed16\" (did "
             "you mean \"fixed16\"?)"}));
}

TEST(ioParse, TablesOfTheWrongKind) {
  EXPECT_EQ(
      messages(R"(format_version = 1
simulation = 60
forces = [1, { type = "gravity" }]
output = "out"
[emitters]
rate = 1
)"),
      (Lines{"bad.toml:2:14: error: simulation: got the integer 60 (expected a [simulation] "
             "table)",
             "bad.toml:3:11: error: forces.0: got the integer 1 (expected a table)",
             "bad.toml:4:10: error: output: got a string \"out\" (expected an [output] table)",
             "bad.toml:5:1: error: emitters: got a table (expected an array of tables, written "
             "[[emitters]])"}));
  EXPECT_EQ(messages("format_version = 1\nemitters = []\n[simulation]\nstep_rate = 60\n"),
            (Lines{"bad.toml:2:12: error: emitters: got an empty array (expected at least one "
                   "[[emitters]] table)"}));
}

TEST(ioParse, FormatVersion) {
  // Unknown versions stop the read: nothing else in the file can be judged.
  EXPECT_EQ(messages("format_version = 2\n[simulation]\nstep_rate = 0\n"),
            (Lines{"bad.toml:1:18: error: format_version: version 2 is not one this build reads "
                   "(expected 1)"}));
  EXPECT_EQ(messages("format_version = 0\n"),
            (Lines{"bad.toml:1:18: error: format_version: version 0 is not one this build reads "
                   "(expected 1)"}));
  // A wrong type or a missing version is reported, and the rest is read as the current version.
  EXPECT_EQ(messages("format_version = \"1\"\n[simulation]\nstep_rate = 0\n[[emitters]]\n"),
            (Lines{"bad.toml:1:18: error: format_version: got a string \"1\" (expected "
                   "format_version = 1)",
                   "bad.toml:3:13: error: simulation.step_rate: 0 is out of range (expected ticks "
                   "per second (Hz), an integer from 1 to 1000000)"}));
}

TEST(ioParse, DuplicateEmitterNames) {
  EXPECT_EQ(
      messages(R"(format_version = 1
[simulation]
step_rate = 60
[[emitters]]
name = "spark"
[[emitters]]
name = "spark"
[[emitters]]
name = "emitter_3"
[[emitters]]
)"),
      (Lines{"bad.toml:7:8: error: emitters.1.name: \"spark\" is already the name of emitters.0 "
             "(expected a name unique among the emitters)",
             // The unnamed fourth emitter defaults to emitter_3, the third's name.
             "bad.toml:10:1: error: emitters.3.name: \"emitter_3\" is already the name of "
             "emitters.2 (expected a name unique among the emitters)"}));
}

TEST(ioParse, SeveralErrorsAreReportedTogetherInFileOrder) {
  EXPECT_EQ(
      messages(R"(format_version = 1

[simulation]
step_rate = 20.5
integrator = "verlet"

[[emitters]]
name = "a"
rate = -1
bursts = [{ time = -2, count = 3, size = 1 }]

[[forces]]
type = "wind"
amplitude = 150
frequency = inf

[output]
fps = 0
)"),
      (Lines{"bad.toml:4:13: error: simulation.step_rate: 20.5 is not an integer (expected "
             "ticks per second (Hz), an integer from 1 to 1000000)",
             "bad.toml:5:14: error: simulation.integrator: unknown integrator \"verlet\" "
             "(expected one of: explicit_euler, semi_implicit_euler, midpoint, "
             "position_verlet, velocity_verlet, rk4)",
             "bad.toml:9:8: error: emitters.0.rate: -1 is out of range (expected particles per "
             "second, a number from 0 to 1e9)",
             "bad.toml:10:20: error: emitters.0.bursts.0.time: -2 is out of range (expected "
             "seconds, a number from 0 to 1e9)",
             "bad.toml:10:35: error: emitters.0.bursts.0.size: unknown key \"size\" (expected "
             "one of: time, count)",
             "bad.toml:15:13: error: forces.0.frequency: inf is not a finite number (expected "
             "hertz, a number from 0 to 1000000)",
             "bad.toml:18:7: error: output.fps: 0 is out of range (expected frames per second, "
             "an integer from 1 to 1000000 or a ratio string like \"30000/1001\")"}));
}

TEST(ioParse, MissingFile) {
  const LoadResult result = loadEffectFile("/nonexistent/effect.toml");
  ASSERT_EQ(result.diagnostics.size(), 1u);
  EXPECT_EQ(result.diagnostics[0].format(),
            "/nonexistent/effect.toml: error: no such file (expected a readable effect file)");
  EXPECT_FALSE(result.ok());
}

TEST(ioParse, BadFileOnDisk) {
  const std::string path = TICKFX_SOURCE_DIR "/tests/data/effects/several_errors.toml";
  const LoadResult result = loadEffectFile(path);
  std::vector<std::string> lines;
  for (const Diagnostic& d : result.diagnostics) lines.push_back(d.format());
  EXPECT_EQ(lines, (Lines{path + ":5:14: error: simulation.integrator: unknown integrator \"rk5\" "
                                 "(did you mean \"rk4\"?)",
                          path + ":9:8: error: emitters.0.rate: nan is not a finite number "
                                 "(expected particles per second, a number from 0 to 1e9)",
                          path + ":14:1: error: forces.0.k: missing (expected a rate in 1/s, a "
                                 "number from 0 to 1e9)",
                          path + ":16:1: error: forces.0.air_speed: unknown key \"air_speed\" "
                                 "(expected one of: type, k, air_velocity)"}));
  // Positions and key paths are fields too, for tools that do not parse the text.
  ASSERT_EQ(result.diagnostics.size(), 4u);
  EXPECT_EQ(result.diagnostics[1].line, 9);
  EXPECT_EQ(result.diagnostics[1].column, 8);
  EXPECT_EQ(result.diagnostics[1].keyPath, "emitters.0.rate");
  EXPECT_EQ(result.diagnostics[1].severity, Severity::Error);
}

// ---- good files -------------------------------------------------------------------------------

TEST(ioParse, MinimalFileGetsTheDocumentedDefaults) {
  const LoadResult result =
      parseEffect("format_version = 1\n[simulation]\nstep_rate = 90\n[[emitters]]\n", "min.toml");
  ASSERT_TRUE(result.ok()) << (result.diagnostics.empty() ? "" : result.diagnostics[0].format());
  EXPECT_TRUE(result.diagnostics.empty());
  const EffectSettings& e = *result.effect;
  EXPECT_EQ(e.formatVersion, 1);
  EXPECT_EQ(e.simulation.stepRateHz, 90);
  EXPECT_EQ(e.simulation.integrator, "semi_implicit_euler");
  EXPECT_EQ(e.simulation.seed, 0u);
  EXPECT_EQ(e.simulation.maxParticles, 1'000'000u);
  EXPECT_EQ(e.simulation.maxTicksPerFrame, 16);
  EXPECT_EQ(e.simulation.overrunPolicy, OverrunPolicy::DropExcess);
  EXPECT_EQ(e.simulation.threads, 0);
  EXPECT_EQ(e.simulation.nonfinite, NonfinitePolicy::Stop);
  ASSERT_EQ(e.emitters.size(), 1u);
  const EmitterSettings& m = e.emitters[0];
  EXPECT_EQ(m.name, "emitter_0");
  EXPECT_EQ(m.position, Eigen::Vector3d::Zero());
  EXPECT_TRUE(std::holds_alternative<PointShape>(m.shape));
  EXPECT_EQ(m.rate, 0.0);
  EXPECT_EQ(m.start, 0.0);
  EXPECT_TRUE(std::isinf(m.stop));
  EXPECT_TRUE(m.bursts.empty());
  EXPECT_EQ(m.direction, Eigen::Vector3d::UnitY());
  EXPECT_EQ(m.speed, 0.0);
  EXPECT_EQ(m.speedJitter, 0.0);
  EXPECT_EQ(m.spreadDegrees, 0.0);
  EXPECT_TRUE(std::isinf(m.lifetime));
  EXPECT_EQ(m.lifetimeJitter, 0.0);
  EXPECT_EQ(m.mass, 1.0);
  EXPECT_TRUE(e.forces.empty());
  EXPECT_EQ(e.output.fps.numerator, 24);
  EXPECT_EQ(e.output.fps.denominator, 1);
  EXPECT_EQ(e.output.seconds, 10.0);
  EXPECT_FALSE(e.output.frames.has_value());
  EXPECT_EQ(e.output.frameCount(), 240);
  EXPECT_EQ(e.output.formats, std::vector<CacheFormat>{CacheFormat::Csv});
  EXPECT_EQ(e.output.directory, "out");
  EXPECT_EQ(e.output.vdb.compression, VdbCacheOptions::Compression::None);
  EXPECT_EQ(e.output.vdb.positions, VdbCacheOptions::Positions::Exact);
  // Shape and force defaults.
  const LoadResult shapes = parseEffect(R"(format_version = 1
[simulation]
step_rate = 60
[[emitters]]
shape = "sphere"
[[emitters]]
shape = "box"
[[emitters]]
shape = "disc"
[[forces]]
type = "gravity"
[[forces]]
type = "wind"
amplitude = 2
frequency = 0.5
[[forces]]
type = "anchor_spring"
stiffness = 3
)",
                                        "shapes.toml");
  ASSERT_TRUE(shapes.ok());
  const auto& sphere = std::get<SphereShape>(shapes.effect->emitters[0].shape);
  EXPECT_EQ(sphere.radius, 1.0);
  EXPECT_FALSE(sphere.surface);
  EXPECT_EQ(std::get<BoxShape>(shapes.effect->emitters[1].shape).size, Eigen::Vector3d::Ones());
  EXPECT_EQ(std::get<DiscShape>(shapes.effect->emitters[2].shape).radius, 1.0);
  EXPECT_EQ(std::get<DiscShape>(shapes.effect->emitters[2].shape).normal, Eigen::Vector3d::UnitY());
  EXPECT_EQ(std::get<GravitySettings>(shapes.effect->forces[0]).acceleration,
            Eigen::Vector3d(0.0, -9.81, 0.0));
  const auto& wind = std::get<WindSettings>(shapes.effect->forces[1]);
  EXPECT_EQ(wind.direction, Eigen::Vector3d::UnitX());
  EXPECT_EQ(wind.base, 0.0);
  EXPECT_EQ(wind.phase, 0.0);
  const auto& spring = std::get<AnchorSpringSettings>(shapes.effect->forces[2]);
  EXPECT_EQ(spring.rest, Eigen::Vector3d::Zero());
  EXPECT_EQ(spring.damping, 0.0);
}

TEST(ioParse, EveryKeyIsRead) {
  const LoadResult result = parseEffect(R"(format_version = 1
[simulation]
step_rate = 240
integrator = "rk4"
seed = 0x2A
max_particles = 5000
max_ticks_per_frame = 4
overrun = "fall_behind"
threads = 3

[[emitters]]
name = "ring"
position = [1, 2.5, -3]
shape = "disc"
radius = 0.75
normal = [0, 0, 2]
rate = 120.5
start = 0.25
stop = 3
bursts = [{ time = 0.5, count = 40 }, { time = 0.1, count = 7 }]
direction = [1, 1, 0]
speed = 4.5
speed_jitter = 0.25
spread = 30
lifetime = 1.5
lifetime_jitter = 0.5
mass = 0.2

[[emitters]]
shape = "sphere"
radius = 2
surface = true

[[emitters]]
shape = "box"
size = [1, 2, 3]

[[forces]]
type = "gravity"
acceleration = [0, -3.7, 0]

[[forces]]
type = "drag"
k = 0.4
air_velocity = [1, 0, -1]

[[forces]]
type = "wind"
direction = [0, 0, 1]
base = 0.5
amplitude = 2.5
frequency = 0.75
phase = 1.25

[[forces]]
type = "anchor_spring"
rest = [0, 1, 0]
stiffness = 8
damping = 0.3

[output]
fps = "30000/1001"
frames = 90
formats = ["ply", "csv"]
directory = "cache/ring"
vdb_compression = "blosc"
vdb_positions = "fixed16"
)",
                                        "all.toml");
  ASSERT_TRUE(result.ok()) << (result.diagnostics.empty() ? "" : result.diagnostics[0].format());
  const EffectSettings& e = *result.effect;
  EXPECT_EQ(e.simulation.stepRateHz, 240);
  EXPECT_EQ(e.simulation.integrator, "rk4");
  EXPECT_EQ(e.simulation.seed, 42u);
  EXPECT_EQ(e.simulation.maxParticles, 5000u);
  EXPECT_EQ(e.simulation.maxTicksPerFrame, 4);
  EXPECT_EQ(e.simulation.overrunPolicy, OverrunPolicy::FallBehind);
  EXPECT_EQ(e.simulation.threads, 3);
  ASSERT_EQ(e.emitters.size(), 3u);
  const EmitterSettings& r = e.emitters[0];
  EXPECT_EQ(r.name, "ring");
  EXPECT_EQ(r.position, Eigen::Vector3d(1.0, 2.5, -3.0));
  const auto& disc = std::get<DiscShape>(r.shape);
  EXPECT_EQ(disc.radius, 0.75);
  EXPECT_EQ(disc.normal, Eigen::Vector3d(0.0, 0.0, 2.0));  // normalised by the emitter, not here
  EXPECT_EQ(r.rate, 120.5);
  EXPECT_EQ(r.start, 0.25);
  EXPECT_EQ(r.stop, 3.0);
  ASSERT_EQ(r.bursts.size(), 2u);
  EXPECT_EQ(r.bursts[0].time, 0.5);
  EXPECT_EQ(r.bursts[0].count, 40u);
  EXPECT_EQ(r.bursts[1].time, 0.1);
  EXPECT_EQ(r.bursts[1].count, 7u);
  EXPECT_EQ(r.direction, Eigen::Vector3d(1.0, 1.0, 0.0));
  EXPECT_EQ(r.speed, 4.5);
  EXPECT_EQ(r.speedJitter, 0.25);
  EXPECT_EQ(r.spreadDegrees, 30.0);
  EXPECT_EQ(r.lifetime, 1.5);
  EXPECT_EQ(r.lifetimeJitter, 0.5);
  EXPECT_EQ(r.mass, 0.2);
  EXPECT_EQ(e.emitters[1].name, "emitter_1");
  EXPECT_EQ(std::get<SphereShape>(e.emitters[1].shape).radius, 2.0);
  EXPECT_TRUE(std::get<SphereShape>(e.emitters[1].shape).surface);
  EXPECT_EQ(std::get<BoxShape>(e.emitters[2].shape).size, Eigen::Vector3d(1.0, 2.0, 3.0));
  ASSERT_EQ(e.forces.size(), 4u);
  EXPECT_EQ(std::get<GravitySettings>(e.forces[0]).acceleration, Eigen::Vector3d(0.0, -3.7, 0.0));
  EXPECT_EQ(std::get<DragSettings>(e.forces[1]).k, 0.4);
  EXPECT_EQ(std::get<DragSettings>(e.forces[1]).airVelocity, Eigen::Vector3d(1.0, 0.0, -1.0));
  const auto& wind = std::get<WindSettings>(e.forces[2]);
  EXPECT_EQ(wind.direction, Eigen::Vector3d(0.0, 0.0, 1.0));
  EXPECT_EQ(wind.base, 0.5);
  EXPECT_EQ(wind.amplitude, 2.5);
  EXPECT_EQ(wind.frequency, 0.75);
  EXPECT_EQ(wind.phase, 1.25);
  const auto& spring = std::get<AnchorSpringSettings>(e.forces[3]);
  EXPECT_EQ(spring.rest, Eigen::Vector3d(0.0, 1.0, 0.0));
  EXPECT_EQ(spring.stiffness, 8.0);
  EXPECT_EQ(spring.damping, 0.3);
  EXPECT_EQ(e.output.fps.numerator, 30000);
  EXPECT_EQ(e.output.fps.denominator, 1001);
  EXPECT_EQ(e.output.frames, std::optional<std::int64_t>(90));
  EXPECT_EQ(e.output.frameCount(), 90);
  EXPECT_EQ(e.output.formats, (std::vector<CacheFormat>{CacheFormat::Ply, CacheFormat::Csv}));
  EXPECT_EQ(e.output.directory, "cache/ring");
  EXPECT_EQ(e.output.vdb.compression, VdbCacheOptions::Compression::Blosc);
  EXPECT_EQ(e.output.vdb.positions, VdbCacheOptions::Positions::Fixed16);
  // Sources: values at their value, defaults at their table's header.
  const SourceLocation rate = e.sources.find("emitters.0.rate");
  EXPECT_EQ(rate.file, "all.toml");
  EXPECT_EQ(rate.line, 17);
  EXPECT_EQ(rate.column, 8);
  const SourceLocation defaulted = e.sources.find("emitters.1.mass");
  EXPECT_EQ(defaulted.line, 29);
  EXPECT_EQ(defaulted.column, 1);
}

TEST(ioParse, OutputDurationInFrames) {
  OutputSettings o;
  o.fps = FrameRate{30000, 1001};
  o.seconds = 10.0;
  EXPECT_EQ(o.frameCount(), 300);  // 299.7 frames: the last one covers the end
  o.fps = FrameRate{24, 1};
  EXPECT_EQ(o.frameCount(), 240);
  o.seconds = 0.1;
  EXPECT_EQ(o.frameCount(), 3);  // 2.4 frames
  o.frames = 7;
  EXPECT_EQ(o.frameCount(), 7);
  EXPECT_DOUBLE_EQ(o.durationSeconds(), 7.0 / 24.0);
}

}  // namespace
}  // namespace tickfx::io
