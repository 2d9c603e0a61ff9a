// Structures in effect files: [[emitters]] of type "rope", "cloth" and "cluster". Their keys and
// every error with its exact message and position, --set on them, the builder against a system
// built by hand, the lint's estimate of their fastest vibration (its messages, and its numbers
// against the core), and the samples that use them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "fields/AnchorSpring.h"
#include "fields/Gravity.h"
#include "fields/SpringNetwork.h"
#include "io/effect/EffectBuilder.h"
#include "io/effect/EffectLint.h"
#include "io/effect/EffectParser.h"
#include "particles/StateHash.h"

namespace tickfx::io {
namespace {

using Lines = std::vector<std::string>;

// Every diagnostic of `text` (read as "bad.toml"), formatted.
Lines messages(std::string_view text, const std::vector<std::string>& overrides = {}) {
  const LoadResult result = parseEffect(text, "bad.toml", overrides);
  Lines out;
  for (const Diagnostic& d : result.diagnostics) out.push_back(d.format());
  if (!out.empty()) {
    EXPECT_FALSE(result.ok()) << "errors but an effect";
  }
  return out;
}

EffectSettings load(std::string_view text, const std::vector<std::string>& overrides = {},
                    std::string_view fileName = "fx.toml") {
  const LoadResult result = parseEffect(text, fileName, overrides);
  for (const Diagnostic& d : result.diagnostics) ADD_FAILURE() << d.format();
  return result.ok() ? *result.effect : EffectSettings{};
}

Lines warnings(const EffectSettings& effect) {
  Lines out;
  for (const Diagnostic& d : lintEffect(effect)) {
    EXPECT_EQ(d.severity, Severity::Warning);
    out.push_back(d.format());
  }
  return out;
}

std::uint64_t hashAfter(ParticleSystem& system, std::int64_t ticks) {
  system.stepTicks(ticks);
  return stateHash(system.pool());
}

// The head of a file: format_version and a [simulation] table (lines 1 to 3).
std::string head(int stepRate = 60, const std::string& integrator = "semi_implicit_euler") {
  return "format_version = 1\n[simulation]\nstep_rate = " + std::to_string(stepRate) +
         "\nintegrator = \"" + integrator + "\"\n";
}

// ---- reading -----------------------------------------------------------------------------------

// Every key of every structure type, between particle emitters (whose indices must not move).
const char* const kEveryKey = R"(format_version = 1
[simulation]
step_rate = 240
seed = 5

[[emitters]]
type = "cluster"
name = "blob"
time = 0.25
mass = 0.03
stiffness = 40.0
damping = 0.01
break_ratio = 1.8
velocity = [0.5, 1.0, 0.0]
lifetime = 3.0
center = [1.0, 2.0, 3.0]
radius = 0.4
count = 120
link_radius = 0.15

[[emitters]]
name = "sparks"
rate = 50.0
speed = 1.0
mass = 0.5

[[emitters]]
type = "rope"
name = "line"
time = 0.0
mass = 0.05
stiffness = 800
damping = 0.2
break_ratio = 0
velocity = [0.0, 0.0, 0.5]
lifetime = 10
start = [0.0, 2.0, 0.0]
end = [1.5, 2.0, 0.0]
count = 16
pin_start = false
pin_end = true

[[emitters]]
type = "cloth"
name = "sheet"
time = 0.5
mass = 0.02
stiffness = 300
damping = 0.05
break_ratio = 2.5
velocity = [0.0, -0.5, 0.0]
lifetime = 4.5
origin = [-1.0, 3.0, 0.0]
axis_u = [2.0, 0.0, 0.0]
axis_v = [0.0, 0.0, 1.0]
width = 9
height = 7
spacing = 0.08
pins = "top_edge"
shear_scale = 0.25
bend_scale = 0.05

[[emitters]]
type = "particles"
name = "dust"
bursts = [{ time = 0.0, count = 30 }]
shape = "sphere"
radius = 0.2

[[forces]]
type = "gravity"

[[forces]]
type = "anchor_spring"
rest = [0.0, 1.0, 0.0]
stiffness = 0.5
damping = 0.01
)";

TEST(ioStructures, EveryKeyIsRead) {
  const EffectSettings e = load(kEveryKey);
  // Particle emitters keep their own numbering: sparks 0, dust 1.
  ASSERT_EQ(e.emitters.size(), 2u);
  EXPECT_EQ(e.emitters[0].name, "sparks");
  EXPECT_EQ(e.emitters[1].name, "dust");
  EXPECT_TRUE(std::holds_alternative<SphereShape>(e.emitters[1].shape));
  // Structures in file order, each with the entry it was read from.
  ASSERT_EQ(e.structures.size(), 3u);
  EXPECT_EQ(e.structureEntries, (std::vector<std::size_t>{0, 2, 3}));
  EXPECT_EQ(structureKeyPath(e, 1), "emitters.2");

  const StructureSettings& blob = e.structures[0];
  EXPECT_EQ(blob.name, "blob");
  EXPECT_EQ(blob.time, 0.25);
  EXPECT_EQ(blob.mass, 0.03);
  EXPECT_EQ(blob.stiffness, 40.0);
  EXPECT_EQ(blob.damping, 0.01);
  EXPECT_EQ(blob.breakRatio, 1.8);
  EXPECT_EQ(blob.velocity, Eigen::Vector3d(0.5, 1.0, 0.0));
  EXPECT_EQ(blob.lifetime, 3.0);
  const auto& cluster = std::get<ClusterShape>(blob.shape);
  EXPECT_EQ(cluster.center, Eigen::Vector3d(1.0, 2.0, 3.0));
  EXPECT_EQ(cluster.radius, 0.4);
  EXPECT_EQ(cluster.count, 120);
  EXPECT_EQ(cluster.linkRadius, 0.15);

  const StructureSettings& line = e.structures[1];
  EXPECT_EQ(line.name, "line");
  EXPECT_EQ(line.time, 0.0);
  EXPECT_EQ(line.mass, 0.05);
  EXPECT_EQ(line.stiffness, 800.0);
  EXPECT_EQ(line.damping, 0.2);
  EXPECT_EQ(line.breakRatio, 0.0);
  EXPECT_EQ(line.velocity, Eigen::Vector3d(0.0, 0.0, 0.5));
  EXPECT_EQ(line.lifetime, 10.0);
  const auto& rope = std::get<RopeShape>(line.shape);
  EXPECT_EQ(rope.start, Eigen::Vector3d(0.0, 2.0, 0.0));
  EXPECT_EQ(rope.end, Eigen::Vector3d(1.5, 2.0, 0.0));
  EXPECT_EQ(rope.count, 16);
  EXPECT_FALSE(rope.pinStart);
  EXPECT_TRUE(rope.pinEnd);

  const StructureSettings& sheet = e.structures[2];
  EXPECT_EQ(sheet.name, "sheet");
  EXPECT_EQ(sheet.time, 0.5);
  EXPECT_EQ(sheet.mass, 0.02);
  EXPECT_EQ(sheet.stiffness, 300.0);
  EXPECT_EQ(sheet.damping, 0.05);
  EXPECT_EQ(sheet.breakRatio, 2.5);
  EXPECT_EQ(sheet.velocity, Eigen::Vector3d(0.0, -0.5, 0.0));
  EXPECT_EQ(sheet.lifetime, 4.5);
  const auto& cloth = std::get<ClothShape>(sheet.shape);
  EXPECT_EQ(cloth.origin, Eigen::Vector3d(-1.0, 3.0, 0.0));
  EXPECT_EQ(cloth.axisU, Eigen::Vector3d(2.0, 0.0, 0.0));  // as written: the core normalises
  EXPECT_EQ(cloth.axisV, Eigen::Vector3d(0.0, 0.0, 1.0));
  EXPECT_EQ(cloth.width, 9);
  EXPECT_EQ(cloth.height, 7);
  EXPECT_EQ(cloth.spacing, 0.08);
  EXPECT_EQ(cloth.pins, ClothPins::TopEdge);
  EXPECT_EQ(cloth.shearStiffnessScale, 0.25);
  EXPECT_EQ(cloth.bendStiffnessScale, 0.05);

  // Where each value was written, for lint.
  EXPECT_EQ(e.sources.find("emitters.2.stiffness").line, 32);
  EXPECT_EQ(e.sources.find("emitters.2.stiffness").column, 13);
}

TEST(ioStructures, MinimalStructuresGetTheDocumentedDefaults) {
  const EffectSettings e = load(head() + R"([[emitters]]
type = "rope"
end = [1, 0, 0]
count = 5
stiffness = 10
[[emitters]]
type = "cloth"
width = 3
height = 4
spacing = 0.5
stiffness = 10
[[emitters]]
type = "cluster"
radius = 1
count = 10
link_radius = 0.5
stiffness = 10
)");
  EXPECT_TRUE(e.emitters.empty());  // a file of structures alone is complete
  ASSERT_EQ(e.structures.size(), 3u);
  for (const StructureSettings& s : e.structures) {
    EXPECT_EQ(s.time, 0.0);
    EXPECT_EQ(s.mass, 1.0);
    EXPECT_EQ(s.damping, 0.0);
    EXPECT_EQ(s.breakRatio, 0.0);
    EXPECT_EQ(s.velocity, Eigen::Vector3d::Zero());
    EXPECT_TRUE(std::isinf(s.lifetime));
  }
  EXPECT_EQ(e.structures[0].name, "rope_0");
  EXPECT_EQ(e.structures[1].name, "cloth_1");
  EXPECT_EQ(e.structures[2].name, "cluster_2");
  const auto& rope = std::get<RopeShape>(e.structures[0].shape);
  EXPECT_EQ(rope.start, Eigen::Vector3d::Zero());
  EXPECT_TRUE(rope.pinStart);
  EXPECT_FALSE(rope.pinEnd);
  const auto& cloth = std::get<ClothShape>(e.structures[1].shape);
  EXPECT_EQ(cloth.origin, Eigen::Vector3d::Zero());
  EXPECT_EQ(cloth.axisU, Eigen::Vector3d::UnitX());
  EXPECT_EQ(cloth.axisV, -Eigen::Vector3d::UnitY());
  EXPECT_EQ(cloth.pins, ClothPins::TopCorners);
  EXPECT_EQ(cloth.shearStiffnessScale, 0.5);
  EXPECT_EQ(cloth.bendStiffnessScale, 0.1);
  EXPECT_EQ(std::get<ClusterShape>(e.structures[2].shape).center, Eigen::Vector3d::Zero());
  // Each pins word.
  for (const auto& [word, pins] :
       std::vector<std::pair<std::string, ClothPins>>{{"none", ClothPins::None},
                                                      {"top_corners", ClothPins::TopCorners},
                                                      {"top_edge", ClothPins::TopEdge},
                                                      {"corners", ClothPins::AllCorners}}) {
    const EffectSettings p = load(head() +
                                  "[[emitters]]\ntype = \"cloth\"\nwidth = 2\nheight = 2\n"
                                  "spacing = 1\nstiffness = 1\npins = \"" +
                                  word + "\"\n");
    ASSERT_EQ(p.structures.size(), 1u);
    EXPECT_EQ(std::get<ClothShape>(p.structures[0].shape).pins, pins) << word;
    EXPECT_EQ(clothPinsName(pins), word);
  }
}

// ---- errors ------------------------------------------------------------------------------------

TEST(ioStructures, UnknownOrMistypedType) {
  EXPECT_EQ(messages(head() + R"([[emitters]]
type = "rop"
end = [1, 0, 0]
[[emitters]]
type = "Cloth"
[[emitters]]
type = "jelly"
count = 3
colour = "red"
rate = 5
[[emitters]]
type = 3
)"),
            (Lines{"bad.toml:6:8: error: emitters.0.type: unknown emitter type \"rop\" (did you "
                   "mean \"rope\"?)",
                   "bad.toml:9:8: error: emitters.1.type: unknown emitter type \"Cloth\" (did you "
                   "mean \"cloth\"?)",
                   // Without a type only unknown keys can be told: count and rate are some
                   // type's keys.
                   "bad.toml:11:8: error: emitters.2.type: unknown emitter type \"jelly\" "
                   "(expected one of: particles, file, rope, cloth, cluster)",
                   "bad.toml:13:1: error: emitters.2.colour: unknown key \"colour\" (expected one "
                   "of: type, name, position, shape, rate, start, stop, bursts, direction, speed, "
                   "speed_jitter, spread, lifetime, lifetime_jitter, mass, attributes, parent, on, "
                   "count, count_range, inherit_velocity, inherit, first_only, size, radius, "
                   "normal, surface, file, time, stiffness, damping, break_ratio, velocity, end, "
                   "pin_start, pin_end, origin, axis_u, axis_v, width, height, spacing, pins, "
                   "shear_scale, bend_scale, center, link_radius)",
                   "bad.toml:16:8: error: emitters.3.type: got the integer 3 (expected emitter "
                   "type, one of: particles, file, rope, cloth, cluster)"}));
}

TEST(ioStructures, MissingRequiredKeysPointAtTheirTable) {
  EXPECT_EQ(
      messages(head() + R"([[emitters]]
type = "rope"
[[emitters]]
type = "cloth"
[[emitters]]
type = "cluster"
)"),
      // At one position, in the order the keys are read: the common keys, then the type's.
      (Lines{"bad.toml:5:1: error: emitters.0.stiffness: missing (expected N/m, a number > 0 and "
             "<= 1e9)",
             "bad.toml:5:1: error: emitters.0.end: missing (expected [x, y, z] in metres, each "
             "from -1e9 to 1e9)",
             "bad.toml:5:1: error: emitters.0.count: missing (expected particles, an integer from "
             "2 to 1000000)",
             "bad.toml:7:1: error: emitters.1.stiffness: missing (expected N/m, a number > 0 and "
             "<= 1e9)",
             "bad.toml:7:1: error: emitters.1.width: missing (expected particles, an integer from "
             "2 to 500000)",
             "bad.toml:7:1: error: emitters.1.height: missing (expected particles, an integer "
             "from 2 to 500000)",
             "bad.toml:7:1: error: emitters.1.spacing: missing (expected metres, a number > 0 and "
             "<= 1e9)",
             "bad.toml:9:1: error: emitters.2.stiffness: missing (expected N/m, a number > 0 and "
             "<= 1e9)",
             "bad.toml:9:1: error: emitters.2.radius: missing (expected metres, a number > 0 and "
             "<= 1e9)",
             "bad.toml:9:1: error: emitters.2.count: missing (expected particles, an integer from "
             "1 to 1000000)",
             "bad.toml:9:1: error: emitters.2.link_radius: missing (expected metres, a number > 0 "
             "and <= 1e9)"}));
}

TEST(ioStructures, ValuesOfTheWrongTypeOrOutOfRange) {
  EXPECT_EQ(
      messages(head() + R"([[emitters]]
type = "rope"
end = [1, 0, 0]
count = 1
stiffness = 0
mass = -1
damping = -0.5
time = -1
lifetime = 0
break_ratio = 0.5
pin_start = "yes"
velocity = [1, 2]
[[emitters]]
type = "cloth"
width = 2.0
height = 1
spacing = 0
stiffness = 1e10
pins = "top"
shear_scale = -0.1
bend_scale = 101
[[emitters]]
type = "cluster"
radius = -1
count = 0
link_radius = inf
stiffness = "stiff"
break_ratio = 1
)"),
      (Lines{"bad.toml:8:9: error: emitters.0.count: 1 is out of range (expected particles, an "
             "integer from 2 to 1000000)",
             "bad.toml:9:13: error: emitters.0.stiffness: 0 is out of range (expected N/m, a "
             "number > 0 and <= 1e9)",
             "bad.toml:10:8: error: emitters.0.mass: -1 is out of range (expected kilograms per "
             "particle, a number > 0 and <= 1e9)",
             "bad.toml:11:11: error: emitters.0.damping: -0.5 is out of range (expected N·s/m, a "
             "number from 0 to 1e9)",
             "bad.toml:12:8: error: emitters.0.time: -1 is out of range (expected seconds, a "
             "number from 0 to 1e9)",
             "bad.toml:13:12: error: emitters.0.lifetime: 0 is out of range (expected seconds, a "
             "number > 0 and <= 1e9)",
             "bad.toml:14:15: error: emitters.0.break_ratio: 0.5 is out of range (expected 0 "
             "(never breaks) or a ratio of the rest length > 1 and <= 1e9)",
             "bad.toml:15:13: error: emitters.0.pin_start: got a string \"yes\" (expected true "
             "or false)",
             "bad.toml:16:12: error: emitters.0.velocity: got 2 entries (expected [x, y, z] in "
             "m/s, each from -1e9 to 1e9)",
             "bad.toml:19:9: error: emitters.1.width: 2.0 is not an integer (expected particles, "
             "an integer from 2 to 500000)",
             "bad.toml:20:10: error: emitters.1.height: 1 is out of range (expected particles, "
             "an integer from 2 to 500000)",
             "bad.toml:21:11: error: emitters.1.spacing: 0 is out of range (expected metres, a "
             "number > 0 and <= 1e9)",
             "bad.toml:22:13: error: emitters.1.stiffness: 10000000000 is out of range (expected "
             "N/m, a number > 0 and <= 1e9)",
             "bad.toml:23:8: error: emitters.1.pins: unknown cloth pins \"top\" (expected one "
             "of: none, top_corners, top_edge, corners)",
             "bad.toml:24:15: error: emitters.1.shear_scale: -0.1 is out of range (expected "
             "times stiffness, a number from 0 to 100)",
             "bad.toml:25:14: error: emitters.1.bend_scale: 101 is out of range (expected times "
             "stiffness, a number from 0 to 100)",
             "bad.toml:28:10: error: emitters.2.radius: -1 is out of range (expected metres, a "
             "number > 0 and <= 1e9)",
             "bad.toml:29:9: error: emitters.2.count: 0 is out of range (expected particles, an "
             "integer from 1 to 1000000)",
             "bad.toml:30:15: error: emitters.2.link_radius: inf is not a finite number (expected "
             "metres, a number > 0 and <= 1e9)",
             "bad.toml:31:13: error: emitters.2.stiffness: got a string \"stiff\" (expected N/m, "
             "a number > 0 and <= 1e9)",
             "bad.toml:32:15: error: emitters.2.break_ratio: 1 is out of range (expected 0 "
             "(never breaks) or a ratio of the rest length > 1 and <= 1e9)"}));
}

TEST(ioStructures, CountsAreHeldToTheirLimits) {
  // At most 10⁶ particles in a structure, and no more than simulation.max_particles.
  EXPECT_EQ(messages(head() + R"([[emitters]]
type = "rope"
end = [1, 0, 0]
count = 1000001
stiffness = 1
[[emitters]]
type = "cloth"
width = 1000
height = 1001
spacing = 0.1
stiffness = 1
[[emitters]]
type = "cluster"
radius = 1
count = 2000000
link_radius = 0.1
stiffness = 1
)"),
            (Lines{"bad.toml:8:9: error: emitters.0.count: 1000001 is out of range (expected "
                   "particles, an integer from 2 to 1000000)",
                   "bad.toml:13:10: error: emitters.1.height: 1000 x 1001 = 1001000 particles are "
                   "too many (expected width x height at most 1000000)",
                   "bad.toml:19:9: error: emitters.2.count: 2000000 is out of range (expected "
                   "particles, an integer from 1 to 1000000)"}));
  EXPECT_EQ(messages(R"(format_version = 1
[simulation]
step_rate = 60
max_particles = 50
[[emitters]]
type = "rope"
end = [1, 0, 0]
count = 51
stiffness = 1
[[emitters]]
type = "cloth"
width = 5
height = 11
spacing = 0.1
stiffness = 1
)"),
            (Lines{"bad.toml:8:9: error: emitters.0.count: 51 is out of range (expected "
                   "particles, an integer from 2 to simulation.max_particles = 50)",
                   "bad.toml:13:10: error: emitters.1.height: 5 x 11 = 55 particles are too many "
                   "(expected width x height at most simulation.max_particles = 50)"}));
  // A cluster whose link radius would join too many pairs: about count · n / 2 springs, n the
  // mean neighbours (here every pair: link_radius >= 2 · radius).
  EXPECT_EQ(messages(head() + R"([[emitters]]
type = "cluster"
radius = 1
count = 5000
link_radius = 2
stiffness = 1
)"),
            (Lines{"bad.toml:9:15: error: emitters.0.link_radius: 2 m would join about 12497500 "
                   "pairs of particles (expected at most 10000000 springs: a link_radius of at "
                   "most 1.37 m for this radius and count)"}));
}

TEST(ioStructures, ShapesThatCannotBeBuilt) {
  EXPECT_EQ(messages(head() + R"([[emitters]]
type = "rope"
start = [1, 2, 3]
end = [1, 2, 3]
count = 3
stiffness = 1
[[emitters]]
type = "cloth"
axis_u = [0, 0, 0]
width = 2
height = 2
spacing = 1
stiffness = 1
[[emitters]]
type = "cloth"
axis_u = [1, 1, 0]
axis_v = [-2, -2, 0]
width = 2
height = 2
spacing = 1
stiffness = 1
[[emitters]]
type = "cloth"
axis_u = [0, 3, 0]
width = 2
height = 2
spacing = 1
stiffness = 1
)"),
            (Lines{"bad.toml:8:7: error: emitters.0.end: is the same point as start (expected [x, "
                   "y, z] in metres, each from -1e9 to 1e9, apart from start: a rope has a "
                   "length)",
                   "bad.toml:13:10: error: emitters.1.axis_u: got [0, 0, 0] (expected a direction "
                   "[x, y, z], each from -1e9 to 1e9, not all zero)",
                   // Shown at the later axis written; with only axis_u written, at axis_u.
                   "bad.toml:21:10: error: emitters.2.axis_v: is parallel to axis_u (expected a "
                   "direction [x, y, z], each from -1e9 to 1e9, not parallel to axis_u)",
                   "bad.toml:28:10: error: emitters.3.axis_u: is parallel to axis_v (expected a "
                   "direction [x, y, z], each from -1e9 to 1e9, not parallel to axis_v)"}));
  // A rope from the default start to [0, 0, 0] is as short.
  EXPECT_EQ(
      messages(head() +
               "[[emitters]]\ntype = \"rope\"\nend = [0, 0, 0]\ncount = 3\nstiffness = 1\n"),
      (Lines{"bad.toml:7:7: error: emitters.0.end: is the same point as start (expected [x, y, z] "
             "in metres, each from -1e9 to 1e9, apart from start: a rope has a length)"}));
}

TEST(ioStructures, ShapesTooSmallForDoublePrecisionCannotBeBuilt) {
  // What only the core refused, reported at load (run used to stop with exit 1 and no
  // position): a rope whose end is 1e-200 m from its start has a length of 0 in double, and a
  // cloth axis of 1e-200 cannot be normalised (it used to be called parallel to the other).
  EXPECT_EQ(messages(head() + R"([[emitters]]
type = "rope"
start = [1e-200, 0, 0]
end = [0, 1e-200, 0]
count = 3
stiffness = 1
[[emitters]]
type = "cloth"
axis_u = [1e-200, 0, 0]
width = 2
height = 2
spacing = 1
stiffness = 1
[[emitters]]
type = "cloth"
axis_u = [1, 0, 0]
axis_v = [0, 0, 1e-160]
width = 2
height = 2
spacing = 1
stiffness = 1
)"),
            (Lines{"bad.toml:8:7: error: emitters.0.end: is 1.41e-200 m from start, "
                   "too close to give the rope a length in double precision (expected [x, y, z] "
                   "in metres, at least 1.5e-154 m from start)",
                   "bad.toml:13:10: error: emitters.1.axis_u: is too short to normalise in double "
                   "precision (expected a direction [x, y, z] at least 1.5e-154 long)",
                   "bad.toml:21:10: error: emitters.2.axis_v: is too short to normalise in double "
                   "precision (expected a direction [x, y, z] at least 1.5e-154 long)"}));
  // The shortest the messages allow builds.
  EXPECT_TRUE(messages(head() + R"([[emitters]]
type = "rope"
end = [0, 0, 1.5e-154]
count = 3
stiffness = 1
[[emitters]]
type = "cloth"
axis_u = [1.5e-154, 0, 0]
width = 2
height = 2
spacing = 1
stiffness = 1
)")
                  .empty());
}

TEST(ioStructures, UnknownKeysGetSuggestions) {
  EXPECT_EQ(messages(head() + R"([[emitters]]
type = "rope"
end = [1, 0, 0]
count = 3
stifness = 1
pin_strat = true
[[emitters]]
type = "cluster"
radius = 1
count = 3
link_radius = 1
stiffness = 1
colour = "green"
)"),
            (Lines{// stifness is unknown, so the rope's stiffness is missing too.
                   "bad.toml:5:1: error: emitters.0.stiffness: missing (expected N/m, a number > 0 "
                   "and <= 1e9)",
                   "bad.toml:9:1: error: emitters.0.stifness: unknown key \"stifness\" (did you "
                   "mean \"stiffness\"?)",
                   "bad.toml:10:1: error: emitters.0.pin_strat: unknown key \"pin_strat\" (did you "
                   "mean \"pin_start\"?)",
                   "bad.toml:17:1: error: emitters.1.colour: unknown key \"colour\" (expected one "
                   "of: type, name, time, mass, stiffness, damping, break_ratio, velocity, "
                   "lifetime, center, radius, count, link_radius)"}));
}

TEST(ioStructures, KeysOfAnotherTypeAreErrors) {
  EXPECT_EQ(
      messages(head() + R"([[emitters]]
type = "rope"
end = [1, 0, 0]
count = 3
stiffness = 1
width = 4
rate = 10
[[emitters]]
type = "cloth"
width = 2
height = 2
spacing = 1
stiffness = 1
link_radius = 0.5
shape = "sphere"
[[emitters]]
rate = 100
stiffness = 5
count = 3
width = 2
)"),
      (Lines{"bad.toml:10:1: error: emitters.0.width: does not apply to an emitter of type "
             "\"rope\" (expected for a rope: type, name, time, mass, stiffness, damping, "
             "break_ratio, velocity, lifetime, start, end, count, pin_start, pin_end)",
             "bad.toml:11:1: error: emitters.0.rate: does not apply to an emitter of type "
             "\"rope\" (expected for a rope: type, name, time, mass, stiffness, damping, "
             "break_ratio, velocity, lifetime, start, end, count, pin_start, pin_end)",
             "bad.toml:18:1: error: emitters.1.link_radius: does not apply to an emitter of type "
             "\"cloth\" (expected for a cloth: type, name, time, mass, stiffness, damping, "
             "break_ratio, velocity, lifetime, origin, axis_u, axis_v, width, height, spacing, "
             "pins, shear_scale, bend_scale)",
             "bad.toml:19:1: error: emitters.1.shape: does not apply to an emitter of type "
             "\"cloth\" (expected for a cloth: type, name, time, mass, stiffness, damping, "
             "break_ratio, velocity, lifetime, origin, axis_u, axis_v, width, height, spacing, "
             "pins, shear_scale, bend_scale)",
             // A particle emitter (no type) with structure keys: the message names the types.
             "bad.toml:22:1: error: emitters.2.stiffness: does not apply to an emitter of type "
             "\"particles\" (expected type = \"rope\", \"cloth\" or \"cluster\" for stiffness)",
             "bad.toml:23:1: error: emitters.2.count: applies to a sub-emitter or a structure "
             "(expected parent = \"NAME\" with it, or type = \"rope\" or \"cluster\")",
             "bad.toml:24:1: error: emitters.2.width: does not apply to an emitter of type "
             "\"particles\" (expected type = \"cloth\" for width)"}));
}

TEST(ioStructures, NamesAreUniqueAmongEveryEmitter) {
  EXPECT_EQ(messages(head() + R"([[emitters]]
name = "a"
[[emitters]]
type = "rope"
name = "a"
end = [1, 0, 0]
count = 3
stiffness = 1
[[emitters]]
name = "rope_3"
[[emitters]]
type = "rope"
end = [1, 0, 0]
count = 3
stiffness = 1
)"),
            (Lines{"bad.toml:9:8: error: emitters.1.name: \"a\" is already the name of emitters.0 "
                   "(expected a name unique among the emitters)",
                   // The unnamed rope defaults to rope_3, the third entry's name.
                   "bad.toml:15:1: error: emitters.3.name: \"rope_3\" is already the name of "
                   "emitters.2 (expected a name unique among the emitters)"}));
}

TEST(ioStructures, EveryErrorAtOnceInFileOrder) {
  EXPECT_EQ(messages(R"(format_version = 1
[simulation]
step_rate = 0
[[emitters]]
type = "cloth"
width = 3
height = 3
spacing = -0.1
stiffness = 10
pins = "top_corner"
[[emitters]]
rate = -5
[[forces]]
type = "gravity"
[[emitters]]
type = "rope"
count = 2.5
stiffness = 10
)"),
            (Lines{"bad.toml:3:13: error: simulation.step_rate: 0 is out of range (expected ticks "
                   "per second (Hz), an integer from 1 to 1000000)",
                   "bad.toml:8:11: error: emitters.0.spacing: -0.1 is out of range (expected "
                   "metres, a number > 0 and <= 1e9)",
                   "bad.toml:10:8: error: emitters.0.pins: unknown cloth pins \"top_corner\" (did "
                   "you mean \"top_corners\"?)",
                   "bad.toml:12:8: error: emitters.1.rate: -5 is out of range (expected particles "
                   "per second, a number from 0 to 1e9)",
                   "bad.toml:15:1: error: emitters.2.end: missing (expected [x, y, z] in metres, "
                   "each from -1e9 to 1e9)",
                   "bad.toml:17:9: error: emitters.2.count: 2.5 is not an integer (expected "
                   "particles, an integer from 2 to 1000000)"}));
}

TEST(ioStructures, OverridesWorkOnStructureKeys) {
  const std::string rope = head() + R"([[emitters]]
type = "rope"
end = [1, 0, 0]
count = 3
stiffness = 1
)";
  const EffectSettings changed =
      load(rope, {"emitters.0.count=40", "emitters.0.pin_end=true", "emitters.0.damping=0.5",
                  "emitters.0.end=[0, -2, 0]"});
  ASSERT_EQ(changed.structures.size(), 1u);
  const auto& shape = std::get<RopeShape>(changed.structures[0].shape);
  EXPECT_EQ(shape.count, 40);
  EXPECT_TRUE(shape.pinEnd);
  EXPECT_EQ(shape.end, Eigen::Vector3d(0.0, -2.0, 0.0));
  EXPECT_EQ(changed.structures[0].damping, 0.5);
  // The type itself can be changed; the rope's keys then do not apply.
  EXPECT_EQ(messages(rope, {"emitters.0.type=cluster", "emitters.0.stiffness=-3"}),
            (Lines{"bad.toml:5:1: error: emitters.0.radius: missing (expected metres, a number > 0 "
                   "and <= 1e9)",
                   "bad.toml:5:1: error: emitters.0.link_radius: missing (expected metres, a "
                   "number > 0 and <= 1e9)",
                   "bad.toml:7:1: error: emitters.0.end: does not apply to an emitter of type "
                   "\"cluster\" (expected for a cluster: type, name, time, mass, stiffness, "
                   "damping, break_ratio, velocity, lifetime, center, radius, count, "
                   "link_radius)",
                   "--set emitters.0.stiffness: error: emitters.0.stiffness: -3 is out of range "
                   "(expected N/m, a number > 0 and <= 1e9)"}));
  EXPECT_EQ(messages(rope, {"emitters.0.type=rop"}),
            (Lines{"--set emitters.0.type: error: emitters.0.type: unknown emitter type \"rop\" "
                   "(did you mean \"rope\"?)"}));
}

// ---- the builder -------------------------------------------------------------------------------

TEST(ioStructures, BuilderEqualsHandBuiltSystem) {
  const EffectSettings effect = load(kEveryKey);

  SystemSettings settings;
  settings.stepRateHz = 240;
  settings.seed = 5;
  EmitterSettings sparks;
  sparks.name = "sparks";
  sparks.rate = 50.0;
  sparks.speed = 1.0;
  sparks.mass = 0.5;
  EmitterSettings dust;
  dust.name = "dust";
  dust.bursts = {Burst{0.0, 30}};
  dust.shape = SphereShape{0.2, false};
  StructureSettings blob;
  blob.name = "blob";
  blob.time = 0.25;
  blob.mass = 0.03;
  blob.stiffness = 40.0;
  blob.damping = 0.01;
  blob.breakRatio = 1.8;
  blob.velocity = Eigen::Vector3d(0.5, 1.0, 0.0);
  blob.lifetime = 3.0;
  blob.shape = ClusterShape{Eigen::Vector3d(1.0, 2.0, 3.0), 0.4, 120, 0.15};
  StructureSettings line;
  line.name = "line";
  line.mass = 0.05;
  line.stiffness = 800.0;
  line.damping = 0.2;
  line.velocity = Eigen::Vector3d(0.0, 0.0, 0.5);
  line.lifetime = 10.0;
  line.shape =
      RopeShape{Eigen::Vector3d(0.0, 2.0, 0.0), Eigen::Vector3d(1.5, 2.0, 0.0), 16, false, true};
  StructureSettings sheet;
  sheet.name = "sheet";
  sheet.time = 0.5;
  sheet.mass = 0.02;
  sheet.stiffness = 300.0;
  sheet.damping = 0.05;
  sheet.breakRatio = 2.5;
  sheet.velocity = Eigen::Vector3d(0.0, -0.5, 0.0);
  sheet.lifetime = 4.5;
  ClothShape cloth;
  cloth.origin = Eigen::Vector3d(-1.0, 3.0, 0.0);
  cloth.axisU = Eigen::Vector3d(2.0, 0.0, 0.0);
  cloth.axisV = Eigen::Vector3d::UnitZ();
  cloth.width = 9;
  cloth.height = 7;
  cloth.spacing = 0.08;
  cloth.pins = ClothPins::TopEdge;
  cloth.shearStiffnessScale = 0.25;
  cloth.bendStiffnessScale = 0.05;
  sheet.shape = cloth;
  ForceSet forces;
  forces.add(std::make_unique<Gravity>(Eigen::Vector3f(0.0f, -9.81f, 0.0f)));
  forces.add(std::make_unique<AnchorSpring>(Eigen::Vector3f(0.0f, 1.0f, 0.0f), 0.5f, 0.01f));
  // The particle emitters numbered 0 and 1 as if the structures were not there; the structures
  // 0, 1, 2 in file order.
  ParticleSystem byHand(settings, {sparks, dust}, std::move(forces), {blob, line, sheet});

  const std::unique_ptr<ParticleSystem> built = buildSystem(effect);
  // 1 s: every structure born (the cluster at 0.25 s, the cloth at 0.5 s), swinging.
  const std::uint64_t expected = hashAfter(byHand, 240);
  EXPECT_EQ(hashAfter(*built, 240), expected);
  EXPECT_EQ(built->pool().size(), 50u + 30u + 120u + 16u + 63u);
  ASSERT_NE(built->springs(), nullptr);
  EXPECT_EQ(built->springs()->springs().size(), byHand.springs()->springs().size());
  EXPECT_GT(built->springs()->springs().size(), 15u + 300u);
  // Structures only: the builder passes them even without a particle emitter.
  const EffectSettings ropeOnly = load(head(240) + R"([[emitters]]
type = "rope"
end = [1, 0, 0]
count = 8
stiffness = 50
)");
  ParticleSystem ropeByHand(ropeOnly.simulation, {}, ForceSet{}, ropeOnly.structures);
  EXPECT_EQ(hashAfter(*buildSystem(ropeOnly), 30), hashAfter(ropeByHand, 30));
}

TEST(ioStructures, EveryStructureKeyReachesTheSimulation) {
  // Changing any one key (through an override) changes the state after one second: no key is
  // read and then dropped on the way to the system. The break_ratio changes go low enough to
  // break more springs than the file's ratios do.
  const std::unique_ptr<ParticleSystem> base = buildSystem(load(kEveryKey));
  const std::uint64_t baseHash = hashAfter(*base, 240);
  const std::vector<std::string> changes = {"emitters.0.time=0.3",
                                            "emitters.0.mass=0.031",
                                            "emitters.0.stiffness=41",
                                            "emitters.0.damping=0.02",
                                            "emitters.0.break_ratio=1.001",
                                            "emitters.0.velocity=[0.5, 1.1, 0]",
                                            "emitters.0.lifetime=0.5",
                                            "emitters.0.center=[1, 2, 3.1]",
                                            "emitters.0.radius=0.41",
                                            "emitters.0.count=119",
                                            "emitters.0.link_radius=0.16",
                                            "emitters.2.time=0.1",
                                            "emitters.2.mass=0.051",
                                            "emitters.2.stiffness=810",
                                            "emitters.2.damping=0.21",
                                            "emitters.2.break_ratio=1.001",
                                            "emitters.2.velocity=[0, 0, 0.6]",
                                            "emitters.2.lifetime=0.9",
                                            "emitters.2.start=[0, 2.1, 0]",
                                            "emitters.2.end=[1.6, 2, 0]",
                                            "emitters.2.count=17",
                                            "emitters.2.pin_start=true",
                                            "emitters.2.pin_end=false",
                                            "emitters.3.time=0.6",
                                            "emitters.3.mass=0.021",
                                            "emitters.3.stiffness=310",
                                            "emitters.3.damping=0.06",
                                            "emitters.3.break_ratio=1.001",
                                            "emitters.3.velocity=[0, -0.6, 0]",
                                            "emitters.3.lifetime=0.4",
                                            "emitters.3.origin=[-1, 3.1, 0]",
                                            "emitters.3.axis_u=[2, 0.1, 0]",
                                            "emitters.3.axis_v=[0, 0.1, 1]",
                                            "emitters.3.width=8",
                                            "emitters.3.height=8",
                                            "emitters.3.spacing=0.09",
                                            "emitters.3.pins=corners",
                                            "emitters.3.shear_scale=0.3",
                                            "emitters.3.bend_scale=0.06"};
  for (const std::string& change : changes) {
    const LoadResult changed = parseEffect(kEveryKey, "every.toml", {change});
    ASSERT_TRUE(changed.ok()) << change;
    EXPECT_NE(hashAfter(*buildSystem(*changed.effect), 240), baseHash) << change;
  }
}

// ---- lint --------------------------------------------------------------------------------------

std::string ropeEffect(int stepRate, const std::string& integrator, double stiffness,
                       double mass = 1.0, double damping = 0.0) {
  return head(stepRate, integrator) + "[[emitters]]\ntype = \"rope\"\nend = [1, 0, 0]\n" +
         "count = 10\nstiffness = " + std::to_string(stiffness) +
         "\nmass = " + std::to_string(mass) + "\ndamping = " + std::to_string(damping) + "\n";
}

TEST(ioStructures, LintRopePastTheStabilityLimitNamesTheStepRate) {
  // k_eff = 4k = 400 N/m, m = 1 kg: ω = 20 rad/s; at 8 Hz ω·dt = 2.5.
  EXPECT_EQ(warnings(load(ropeEffect(8, "semi_implicit_euler", 100.0), {}, "lint.toml")),
            (Lines{"lint.toml:9:13: warning: emitters.0.stiffness: omega*dt = 2.5 is past "
                   "semi_implicit_euler's stability limit of 2 (omega = sqrt(k_eff/m) = 20 rad/s, "
                   "k_eff = 4k = 400 N/m for a rope's springs, m = 1 kg, and dt = 1/8 s): the "
                   "rope's fastest vibration grows without bound (use a step_rate of at least 11 "
                   "Hz)"}));
  EXPECT_TRUE(warnings(load(ropeEffect(11, "semi_implicit_euler", 100.0))).empty());
  // Exactly at the limit (ω·dt = 2 at 10 Hz) is past it, as for the anchor spring.
  EXPECT_EQ(warnings(load(ropeEffect(10, "velocity_verlet", 100.0))).size(), 1u);
  // RK4 and midpoint have their own limits: 20/7 = 2.857 > 2.785, 20/14 = 1.43 > 1.414.
  const Lines rk4 = warnings(load(ropeEffect(7, "rk4", 100.0)));
  ASSERT_EQ(rk4.size(), 1u);
  EXPECT_NE(rk4[0].find("omega*dt = 2.857 is past rk4's stability limit of 2.785"),
            std::string::npos);
  EXPECT_NE(rk4[0].find("(use a step_rate of at least 8 Hz)"), std::string::npos);
  EXPECT_TRUE(warnings(load(ropeEffect(8, "rk4", 100.0))).empty());
  const Lines midpoint = warnings(load(ropeEffect(14, "midpoint", 100.0)));
  ASSERT_EQ(midpoint.size(), 1u);
  EXPECT_NE(midpoint[0].find("(use a step_rate of at least 15 Hz)"), std::string::npos);
  // Midpoint's loss in the fastest vibration is not warned about (it damps the jitter).
  EXPECT_TRUE(warnings(load(ropeEffect(15, "midpoint", 100.0))).empty());
}

TEST(ioStructures, LintClothAndClusterEstimates) {
  // Cloth: k_eff = 4k(1 + 0.5 + 0.1) = 640 N/m, m = 0.1 kg: ω = 80 rad/s; RK4 at 25 Hz.
  EXPECT_EQ(warnings(load(head(25, "rk4") + R"([[emitters]]
type = "cloth"
width = 4
height = 3
spacing = 0.1
mass = 0.1
stiffness = 100
)",
                          {}, "lint.toml")),
            (Lines{"lint.toml:11:13: warning: emitters.0.stiffness: omega*dt = 3.2 is past rk4's "
                   "stability limit of 2.785 (omega = sqrt(k_eff/m) = 80 rad/s, k_eff = 4k(1 + "
                   "shear_scale + bend_scale) = 640 N/m for a cloth's springs, m = 0.1 kg, and dt "
                   "= 1/25 s): the cloth's fastest vibration grows without bound (use a step_rate "
                   "of at least 29 Hz)"}));
  // Cluster: n = 1000 · (0.5³ − 9·0.5⁴/16 + 0.5⁶/32) = 90.33 mean neighbours; k_eff =
  // (n + 3√n)·k = 1188 N/m; m = 0.01 kg: ω = 344.7 rad/s; at 120 Hz ω·dt = 2.873.
  EXPECT_EQ(warnings(load(head(120, "velocity_verlet") + R"([[emitters]]
type = "cluster"
radius = 1.0
count = 1001
link_radius = 0.5
mass = 0.01
stiffness = 10
)",
                          {}, "lint.toml")),
            (Lines{"lint.toml:11:13: warning: emitters.0.stiffness: omega*dt = 2.873 is past "
                   "velocity_verlet's stability limit of 2 (omega = sqrt(k_eff/m) = 344.7 rad/s, "
                   "k_eff = (n + 3*sqrt(n))*k = 1188 N/m for a cluster's springs, n = 90.33 "
                   "neighbours of a particle on average, m = 0.01 kg, and dt = 1/120 s): the "
                   "cluster's fastest vibration grows without bound (use a step_rate of at least "
                   "173 Hz)"}));
  // The pieces of the estimate.
  StructureSettings s;
  s.stiffness = 2.0;
  s.shape = ClusterShape{Eigen::Vector3d::Zero(), 1.0, 1001, 0.5};
  EXPECT_NEAR(structureStiffness(s).neighbours.value(), 90.33203125, 1e-9);
  EXPECT_NEAR(structureStiffness(s).stiffness, 2.0 * (90.33203125 + 3.0 * std::sqrt(90.33203125)),
              1e-9);
  s.shape = ClusterShape{Eigen::Vector3d::Zero(), 1.0, 50, 2.0};  // every pair joined
  EXPECT_EQ(structureStiffness(s).stiffness, 2.0 * 50);
  EXPECT_EQ(structureStiffness(s).formula, "count*k");
  s.shape = ClusterShape{Eigen::Vector3d::Zero(), 1.0, 100, 0.1};  // n = 0.093: chance pairs
  EXPECT_EQ(structureStiffness(s).stiffness, 2.0 * 4);
  s.shape = ClusterShape{Eigen::Vector3d::Zero(), 1.0, 1, 0.5};  // one particle, no springs
  EXPECT_EQ(structureStiffness(s).stiffness, 0.0);
  s.shape = ClothShape{};
  EXPECT_DOUBLE_EQ(structureStiffness(s).stiffness, 2.0 * 4.0 * 1.6);
  s.shape = RopeShape{};
  EXPECT_EQ(structureStiffness(s).stiffness, 8.0);
}

TEST(ioStructures, LintWarnsAboutTheStiffestStructureOnly) {
  // A soft rope, a particle emitter and a stiff rope past the limit: the stiff one (entry 2, the
  // second structure) is named.
  const std::string text = head(8) + R"([[emitters]]
type = "rope"
end = [1, 0, 0]
count = 4
stiffness = 30
[[emitters]]
rate = 1
[[emitters]]
type = "rope"
end = [0, 1, 0]
count = 4
stiffness = 100
mass = 0.25
)";
  const Lines w = warnings(load(text, {}, "lint.toml"));
  ASSERT_EQ(w.size(), 1u);
  EXPECT_EQ(w[0].rfind("lint.toml:16:13: warning: emitters.2.stiffness: omega*dt = 5 is past", 0),
            0u);
  EXPECT_NE(w[0].find("(use a step_rate of at least 21 Hz)"), std::string::npos);
  // Through --set, the warning names the override.
  const Lines set = warnings(load(text, {"emitters.2.stiffness=50"}));
  ASSERT_EQ(set.size(), 1u);
  EXPECT_EQ(set[0].rfind("--set emitters.2.stiffness: warning: emitters.2.stiffness: omega*dt = "
                         "3.536 is past",
                         0),
            0u);
  // Settings made in code have no entry: the key path is the structure's own.
  EffectSettings code = load(text);
  code.structureEntries.clear();
  code.sources = SourceMap{};
  const Lines fromCode = warnings(code);
  ASSERT_EQ(fromCode.size(), 1u);
  EXPECT_EQ(fromCode[0].rfind("<effect>: warning: structures.1.stiffness: omega*dt = 5 is past", 0),
            0u);
}

TEST(ioStructures, LintAddsAnchorSpringsToTheStructure) {
  // The anchor spring pulls on the rope's particles too: k_eff = 4·100 + 100 = 500 N/m, ω =
  // 22.36 rad/s, past the limit at 11 Hz where the rope alone (20/11 = 1.82) and the anchor
  // alone (10/11) are not.
  const std::string text = ropeEffect(11, "semi_implicit_euler", 100.0) + R"([[forces]]
type = "anchor_spring"
stiffness = 100
)";
  EXPECT_EQ(warnings(load(text, {}, "lint.toml")),
            (Lines{"lint.toml:9:13: warning: emitters.0.stiffness: omega*dt = 2.033 is past "
                   "semi_implicit_euler's stability limit of 2 (omega = sqrt(k_eff/m) = 22.36 "
                   "rad/s, k_eff = 4k + 100 = 500 N/m for a rope's springs and the anchor "
                   "springs, m = 1 kg, and dt = 1/11 s): the rope's fastest vibration grows "
                   "without bound (use a step_rate of at least 12 Hz)"}));
  EXPECT_TRUE(warnings(load(text, {"simulation.step_rate=12"})).empty());
  // Without particle emitters, the anchor spring's own check takes the structures' mass.
  const Lines light = warnings(load(ropeEffect(8, "semi_implicit_euler", 1.0, 0.25) + R"([[forces]]
type = "anchor_spring"
stiffness = 100
)"));
  ASSERT_EQ(light.size(), 2u);
  EXPECT_NE(light[0].find("emitters.0.stiffness: omega*dt = 2.55 is past"), std::string::npos);
  EXPECT_NE(light[1].find("forces.0.stiffness: omega*dt = 2.5 is past semi_implicit_euler's "
                          "stability limit of 2 (omega = sqrt(k/m) = 20 rad/s for the lightest "
                          "mass, 0.25 kg"),
            std::string::npos);
}

TEST(ioStructures, LintExplicitEulerGainsEnergyInTheFastestVibration) {
  // k_eff = 400 N/m, m = 1 kg at 240 Hz: × 1 + (400/240)/240 = 1.006944 a step.
  EXPECT_EQ(warnings(load(ropeEffect(240, "explicit_euler", 100.0), {}, "lint.toml")),
            (Lines{"lint.toml:9:13: warning: emitters.0.stiffness: explicit_euler adds energy to "
                   "this rope's springs every step (x1.00694 per step, x1.63e+07 over the 10 s "
                   "of output, for its fastest vibration) (use semi_implicit_euler, "
                   "position_verlet or velocity_verlet, damping of at least 0.4167 N·s/m (k·dt), "
                   "or a step_rate of at least 401997 Hz to keep the gain over the output under "
                   "1%)"}));
  // Each spring's damping of k·dt stops the gain.
  EXPECT_TRUE(warnings(load(ropeEffect(240, "explicit_euler", 100.0, 1.0, 0.4167))).empty());
  // Far too stiff for explicit Euler at all: the stability warning does not apply (there is no
  // limit), the gain does, without bound.
  const Lines huge = warnings(load(ropeEffect(60, "explicit_euler", 1e6)));
  ASSERT_EQ(huge.size(), 1u);
  EXPECT_NE(huge[0].find("beyond x1e308 over the 10 s of output"), std::string::npos);
}

// The largest |coordinate| of any particle after `ticks`, or infinity once it is not finite.
float largestExcursion(ParticleSystem& system, int ticks) {
  system.stepTicks(ticks);
  float largest = 0.0f;
  const auto n = static_cast<Eigen::Index>(system.pool().size());
  for (int c = 0; c < 3; ++c) {
    const auto column = system.pool().position()[c].head(n);
    if (!column.allFinite()) return std::numeric_limits<float>::infinity();
    largest = std::max(largest, column.abs().maxCoeff());
  }
  return largest;
}

TEST(ioStructures, LintEstimateIsTheCoresOwn) {
  // The estimate against the core: a structure stepped at a rate where the estimated ω·dt is
  // 0.95 × the limit stays in place; at 1.1 × (ropes, cloth) it flies apart. Gravity stirs it.
  struct Case {
    std::string name;
    std::string keys;   // of the [[emitters]] entry
    double overFactor;  // the ω·dt factor (of the limit) that must fly apart
  };
  const std::vector<Case> cases = {
      {"rope", "type = \"rope\"\nend = [1.5, 0, 0]\ncount = 30\nstiffness = 1000\nmass = 0.1\n",
       1.1},
      // Structural and shear springs only: the estimate 4k(1 + shear) is exact then.
      {"cloth",
       "type = \"cloth\"\nwidth = 12\nheight = 10\nspacing = 0.1\nbend_scale = 0\n"
       "stiffness = 1000\nmass = 0.1\n",
       1.1},
      // A cluster's estimate is an upper bound (ω is 0.83 times it here): it flies apart at
      // 1.35 ×.
      {"cluster",
       "type = \"cluster\"\nradius = 0.5\ncount = 100\nlink_radius = 0.5\nstiffness = 1000\n"
       "mass = 0.1\n",
       1.35},
  };
  for (const Case& c : cases) {
    for (const std::string& integrator : {std::string("semi_implicit_euler"), std::string("rk4")}) {
      const std::string text =
          head(60, integrator) + "[[emitters]]\n" + c.keys + "[[forces]]\ntype = \"gravity\"\n";
      const EffectSettings effect = load(text);
      ASSERT_EQ(effect.structures.size(), 1u);
      const double omega =
          std::sqrt(structureStiffness(effect.structures[0]).stiffness / effect.structures[0].mass);
      const double limit = springStabilityLimit(integrator).value();
      for (const double factor : {0.95, c.overFactor}) {
        const auto rate = static_cast<std::int64_t>(std::lround(omega / (factor * limit)));
        EffectSettings stepped = effect;
        stepped.simulation.stepRateHz = rate;
        stepped.simulation.maxTicksPerFrame = 100'000;  // not the lint under test
        stepped.simulation.threads = 1;
        EXPECT_EQ(lintEffect(stepped).empty(), factor < 1.0) << c.name << " " << integrator;
        const std::unique_ptr<ParticleSystem> system = buildSystem(stepped);
        const float excursion = largestExcursion(*system, 400);
        if (factor < 1.0) {
          EXPECT_LT(excursion, 100.0f) << c.name << " " << integrator << " at " << rate << " Hz";
        } else if (integrator == "semi_implicit_euler") {
          // RK4's limit is its real-axis radius, below its reach on springs: it holds longer.
          EXPECT_FALSE(excursion < 1e6f) << c.name << " at " << rate << " Hz";
        }
      }
    }
  }
}

// ---- samples -----------------------------------------------------------------------------------

std::filesystem::path samplePath(const std::string& name) {
  return std::filesystem::path(TICKFX_SOURCE_DIR) / "samples" / (name + ".toml");
}

EffectSettings loadSample(const std::string& name, const std::vector<std::string>& overrides = {}) {
  const LoadResult result = loadEffectFile(samplePath(name), overrides);
  for (const Diagnostic& d : result.diagnostics) ADD_FAILURE() << d.format();
  return result.ok() ? *result.effect : EffectSettings{};
}

class ioStructureSamples : public ::testing::TestWithParam<std::string> {};

TEST_P(ioStructureSamples, LoadLintCleanBuildAndRun) {
  const EffectSettings effect = loadSample(GetParam());
  ASSERT_EQ(effect.structures.size(), 1u);
  for (const Diagnostic& d : lintEffect(effect)) ADD_FAILURE() << d.format();
  const std::unique_ptr<ParticleSystem> system = buildSystem(effect, 2);
  // A few frames through the driver, as a player would.
  const Flicks frame = frameDuration(effect.output.fps);
  std::int64_t ticks = 0;
  for (int f = 0; f < 5; ++f) ticks += system->advance(frame).ticks;
  EXPECT_EQ(system->tickCount(), ticks);
  EXPECT_GT(ticks, 0);
  ASSERT_NE(system->springs(), nullptr);
  EXPECT_FALSE(system->springs()->springs().empty());
  EXPECT_GT(system->pool().size(), 0u);
}

INSTANTIATE_TEST_SUITE_P(Samples, ioStructureSamples,
                         ::testing::Values("rope_swing", "flag", "jelly"),
                         [](const ::testing::TestParamInfo<std::string>& sample) {
                           return sample.param;
                         });

TEST(ioStructureSamplesMotion, RopeSwingsDownFromItsPin) {
  const std::unique_ptr<ParticleSystem> system = buildSystem(loadSample("rope_swing"), 1);
  const auto& p = system->pool().position();
  system->stepTicks(240);  // 0.5 s
  // The pinned end stays put, the free end has fallen and swung towards the pin.
  EXPECT_EQ(p.x[0], 0.0f);
  EXPECT_EQ(p.y[0], 2.0f);
  EXPECT_LT(p.y[23], 1.5f);
  EXPECT_LT(p.x[23], 2.0f);
  // Half a swing later it is on the other side of the pin.
  system->stepTicks(240);
  EXPECT_LT(p.x[23], 0.0f);
  EXPECT_EQ(system->springs()->springs().size(), 23u);
  // The sample's step rate is 1.32 rad a step: at 300 Hz the lint warns (ω = 632.5 rad/s).
  const Lines slow = warnings(loadSample("rope_swing", {"simulation.step_rate=300"}));
  ASSERT_EQ(slow.size(), 1u);
  EXPECT_NE(slow[0].find("omega*dt = 2.108 is past semi_implicit_euler's stability limit of 2"),
            std::string::npos);
  EXPECT_NE(slow[0].find("(use a step_rate of at least 317 Hz)"), std::string::npos);
}

TEST(ioStructureSamplesMotion, FlagIsBlownOutFromItsPole) {
  const std::unique_ptr<ParticleSystem> system = buildSystem(loadSample("flag"), 1);
  system->stepTicks(2 * 600);  // 2 s
  const auto& p = system->pool().position();
  const auto n = static_cast<Eigen::Index>(system->pool().size());
  ASSERT_EQ(n, 160);
  // Row 0 (the first 10 particles) is on the pole, the rest is blown away from it.
  for (int i = 0; i < 10; ++i) EXPECT_EQ(p.x[i], 0.0f) << i;
  EXPECT_GT(p.x.head(n).mean(), 0.4f);
  EXPECT_GT(p.x[n - 1], 1.0f);
  // The gusts move it across: its far edge does not stay in the plane it started in.
  EXPECT_GT(p.z.head(n).abs().maxCoeff(), 0.1f);
}

TEST(ioStructureSamplesMotion, JellyFallsBouncesAndKeepsItsShape) {
  const std::unique_ptr<ParticleSystem> system = buildSystem(loadSample("jelly"), 1);
  const auto& p = system->pool().position();
  float lowest = 10.0f, highestAfterLowest = -10.0f;
  for (int step = 0; step < 36; ++step) {  // 3 s, every 1/12 s
    system->stepTicks(10);
    const auto n = static_cast<Eigen::Index>(system->pool().size());
    ASSERT_EQ(n, 150);
    const float y = p.y.head(n).mean();
    if (y < lowest) {
      lowest = y;
      highestAfterLowest = y;
    }
    highestAfterLowest = std::max(highestAfterLowest, y);
    // Still a ball of about 60 cm across, never crushed nor torn apart.
    const float width = p.x.head(n).maxCoeff() - p.x.head(n).minCoeff();
    EXPECT_GT(width, 0.35f) << step;
    EXPECT_LT(width, 0.8f) << step;
  }
  EXPECT_LT(lowest, 0.0f);              // it fell 3 m and more on the bungee
  EXPECT_GT(highestAfterLowest, 2.0f);  // and came back up
}

}  // namespace
}  // namespace tickfx::io
