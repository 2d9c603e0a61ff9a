// --set key.path=value: values of every kind, validation through the same messages, and the
// errors of overrides that cannot be applied.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "io/effect/EffectParser.h"
#include "io/effect/SettingOverrides.h"

namespace tickfx::io {
namespace {

using Lines = std::vector<std::string>;

const char* const kEffect = R"(format_version = 1
[simulation]
step_rate = 60
integrator = "semi_implicit_euler"

[[emitters]]
name = "spray"
rate = 100
bursts = [{ time = 0.5, count = 10 }]

[[forces]]
type = "gravity"

[[forces]]
type = "wind"
amplitude = 2.0
frequency = 1.0
)";

LoadResult load(const std::vector<std::string>& overrides, const char* text = kEffect) {
  return parseEffect(text, "fx.toml", overrides);
}

Lines messages(const std::vector<std::string>& overrides, const char* text = kEffect) {
  Lines out;
  for (const Diagnostic& d : load(overrides, text).diagnostics) out.push_back(d.format());
  return out;
}

TEST(ioOverrides, ValuesOfEveryKind) {
  const LoadResult r = load({"simulation.step_rate=120",
                             "simulation.integrator=rk4",      // a plain word
                             "emitters.0.name=\"fine mist\"",  // a quoted string
                             "emitters.0.shape=sphere",
                             "emitters.0.surface=true",           // a boolean
                             "emitters.0.position=[1, 2.5, -3]",  // an array
                             "emitters.0.bursts.0.count=25",      // inside an inline table
                             "forces.1.frequency=16",             // an integer for a number
                             " forces.1.phase = 0.5 "});          // spaces are trimmed
  ASSERT_TRUE(r.ok()) << (r.diagnostics.empty() ? "" : r.diagnostics[0].format());
  const EffectSettings& e = *r.effect;
  EXPECT_EQ(e.simulation.stepRateHz, 120);
  EXPECT_EQ(e.simulation.integrator, "rk4");
  EXPECT_EQ(e.emitters[0].name, "fine mist");
  EXPECT_TRUE(std::get<SphereShape>(e.emitters[0].shape).surface);
  EXPECT_EQ(e.emitters[0].position, Eigen::Vector3d(1.0, 2.5, -3.0));
  EXPECT_EQ(e.emitters[0].bursts[0].count, 25u);
  EXPECT_EQ(std::get<WindSettings>(e.forces[1]).frequency, 16.0);
  EXPECT_EQ(std::get<WindSettings>(e.forces[1]).phase, 0.5);
  // Where an overridden value came from, for lint.
  const SourceLocation at = e.sources.find("forces.1.frequency");
  EXPECT_EQ(at.file, "--set forces.1.frequency");
  EXPECT_EQ(at.line, 0);
}

TEST(ioOverrides, KeysAndTablesMissingFromTheFileAreAdded) {
  const LoadResult r =
      load({"simulation.threads=2", "output.fps=\"30000/1001\"", "output.frames=12",
            "emitters.0.bursts.0={ time = 2.0, count = 3 }",
            "emitters.0.bursts=[{ time = 1.0, count = 4 }, { time = 3.0, count = 5 }]"});
  ASSERT_TRUE(r.ok()) << (r.diagnostics.empty() ? "" : r.diagnostics[0].format());
  EXPECT_EQ(r.effect->simulation.threads, 2);
  EXPECT_EQ(r.effect->output.fps.numerator, 30000);
  EXPECT_EQ(r.effect->output.frameCount(), 12);
  // Later overrides win: the whole array replaced the entry set before it.
  ASSERT_EQ(r.effect->emitters[0].bursts.size(), 2u);
  EXPECT_EQ(r.effect->emitters[0].bursts[1].count, 5u);
}

TEST(ioOverrides, OverriddenValuesAreValidatedWithTheSameMessages) {
  // Reported in command-line order, each under the override that gave the value.
  EXPECT_EQ(
      messages({"simulation.step_rate=0", "forces.1.frequency=nan", "simulation.integrator=rk5",
                "emitters.0.rate=fast"}),
      (Lines{"--set simulation.step_rate: error: simulation.step_rate: 0 is out of range "
             "(expected ticks per second (Hz), an integer from 1 to 1000000)",
             "--set forces.1.frequency: error: forces.1.frequency: nan is not a finite number "
             "(expected hertz, a number from 0 to 1000000)",
             "--set simulation.integrator: error: simulation.integrator: unknown integrator "
             "\"rk5\" (did you mean \"rk4\"?)",
             "--set emitters.0.rate: error: emitters.0.rate: got a string \"fast\" (expected "
             "particles per second, a number from 0 to 1e9)"}));
}

TEST(ioOverrides, UnknownKeysGetSuggestionsInCommandLineOrder) {
  EXPECT_EQ(
      messages({"simulation.integratr=rk4", "forces.0.k=3", "simulaton.step_rate=30"}),
      (Lines{"--set simulation.integratr: error: simulation.integratr: unknown key "
             "\"integratr\" (did you mean \"integrator\"?)",
             "--set forces.0.k: error: forces.0.k: does not apply to a force of type "
             "\"gravity\" (expected for gravity: type, acceleration)",
             "--set simulaton.step_rate: error: simulaton: unknown key \"simulaton\" (did you "
             "mean \"simulation\"?)"}));
}

TEST(ioOverrides, PathsThatDoNotExist) {
  EXPECT_EQ(
      messages({"forces.9.frequency=16", "emitters.0.bursts.3.count=2", "emitters.first.rate=3",
                "simulation.step_rate.hz=60", "outputs.0.fps=24"}),
      (Lines{"--set forces.9.frequency: error: forces.9: no such entry: forces has 2 entries "
             "(expected an entry number from 0 to 1)",
             "--set emitters.0.bursts.3.count: error: emitters.0.bursts.3: no such entry: "
             "emitters.0.bursts has 1 entry (expected entry number 0)",
             "--set emitters.first.rate: error: emitters.first: emitters is an array (expected "
             "entry number 0)",
             "--set simulation.step_rate.hz: error: simulation.step_rate: is an integer, not a "
             "table (expected a path through tables and arrays)",
             "--set outputs.0.fps: error: outputs: no such array (expected entries written in "
             "the file: --set changes them, it does not add them)"}));
}

TEST(ioOverrides, MalformedOverrides) {
  EXPECT_EQ(
      messages({"simulation.step_rate", "simulation..seed=1", "=5",
                "simulation.seed=", "emitters.0.name=two words", "emitters.0.rate=[1, 2"}),
      (Lines{"--set simulation.step_rate: error: malformed override (expected key.path=value, "
             "e.g. simulation.step_rate=120)",
             "--set simulation..seed=1: error: malformed key path \"simulation..seed\" "
             "(expected keys and entry numbers joined by dots, e.g. forces.1.frequency)",
             "--set =5: error: malformed key path \"\" (expected keys and entry numbers joined "
             "by dots, e.g. forces.1.frequency)",
             "--set simulation.seed: error: simulation.seed: missing value (expected "
             "key.path=value)",
             "--set emitters.0.name: error: emitters.0.name: cannot read \"two words\" as a "
             "value (expected a TOML value: a number, true or false, a word or a quoted string, "
             "an array like [1, 2, 3])",
             "--set emitters.0.rate: error: emitters.0.rate: cannot read \"[1, 2\" as a value "
             "(expected a TOML value: a number, true or false, a word or a quoted string, an "
             "array like [1, 2, 3])"}));
}

TEST(ioOverrides, FileErrorsComeFirstThenOverrides) {
  const char* const bad = "format_version = 1\n[simulation]\nstep_rate = -1\n[[emitters]]\n";
  EXPECT_EQ(messages({"forces.0.type=gravity", "emitters.0.mass=0"}, bad),
            (Lines{"fx.toml:3:13: error: simulation.step_rate: -1 is out of range (expected ticks "
                   "per second (Hz), an integer from 1 to 1000000)",
                   "--set forces.0.type: error: forces: no such array (expected entries written in "
                   "the file: --set changes them, it does not add them)",
                   "--set emitters.0.mass: error: emitters.0.mass: 0 is out of range (expected "
                   "kilograms, a number > 0 and <= 1e9)"}));
  // Fixing the file's error from the command line works too.
  EXPECT_TRUE(load({"simulation.step_rate=30"}, bad).ok());
}

TEST(ioOverrides, FormatVersionIsNotOverridable) {
  EXPECT_EQ(messages({"format_version=1"}),
            (Lines{"--set format_version: error: format_version: cannot be changed by an override "
                   "(expected the version the file is written in)"}));
}

TEST(ioOverrides, MalformedTomlHidesTheOverrides) {
  // The document cannot be read, so there is nothing to apply overrides to.
  EXPECT_EQ(
      messages({"simulation.step_rate=0"}, "format_version = 1\n[simulation\n"),
      (Lines{"fx.toml:2:12: error: Error while parsing table header: expected ']', saw '\\n'"}));
}

TEST(ioOverrides, ApplyOverridesOnATable) {
  // The function the loader uses, on its own.
  toml::table document = toml::parse("[a]\nb = 1\nlist = [{ c = 2 }]\n");
  OverrideOrigins origins;
  const std::vector<Diagnostic> errors =
      applyOverrides(document, {"a.b=5", "a.list.0.c=word", "a.new.deep=true"}, origins);
  EXPECT_TRUE(errors.empty());
  EXPECT_EQ(document["a"]["b"].value<std::int64_t>(), 5);
  EXPECT_EQ(document["a"]["list"][0]["c"].value<std::string>(), "word");
  EXPECT_EQ(document["a"]["new"]["deep"].value<bool>(), true);
  ASSERT_NE(origins.labelOf(*document["a"]["b"].node()), nullptr);
  EXPECT_EQ(*origins.labelOf(*document["a"]["b"].node()), "--set a.b");
  EXPECT_EQ(*origins.labelOf(*document["a"]["new"].node()), "--set a.new.deep");
  EXPECT_EQ(origins.labelOf(*document["a"].node()), nullptr);  // from the file
}

}  // namespace
}  // namespace tickfx::io
