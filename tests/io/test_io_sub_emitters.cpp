// Sub-emitters and attributes over life in effect files: the keys, their errors at their place,
// the lint, every cache format with Houdini's names, and a checkpoint taken while children wait.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <string>
#include <vector>

#include "VdbTestData.h"
#include "io/cache/CsvCache.h"
#include "io/cache/FrameData.h"
#include "io/cache/PlyCache.h"
#include "io/cache/VdbPointCache.h"
#include "io/effect/EffectBuilder.h"
#include "io/effect/EffectLint.h"
#include "io/effect/EffectParser.h"
#include "io/state/Checkpoint.h"
#include "particles/StateHash.h"
#include "tests/support/FileBytes.h"

namespace tickfx::io {
namespace {

constexpr const char* kHead = R"(format_version = 1
[simulation]
step_rate = 60
seed = 4
)";

// Shells that burst into sparks whose colour, opacity and size follow their life.
constexpr const char* kFireworks = R"(
[[emitters]]
name = "shells"
bursts = [{time = 0.0, count = 4}]
speed = 12.0
spread = 20.0
lifetime = 0.5
attributes = { Cd = [1.0, 0.8, 0.5], pscale = 0.1, Alpha = 1.0 }

[[emitters]]
name = "sparks"
parent = "shells"
on = "death"
count_range = [20, 30]
inherit_velocity = 0.5
speed = 4.0
spread = 180.0
lifetime = 1.0
inherit = ["pscale"]

[emitters.attributes]
Cd = { ramp = [[0.0, [1.0, 1.0, 1.0]], [1.0, [0.3, 0.0, 0.0]]], interpolation = "smooth" }
Alpha = { ramp = [[0.0, 1.0], [1.0, 0.0]] }
heat = { random = [700.0, 900.0] }

[[forces]]
type = "gravity"
)";

EffectSettings load(const std::string& text) {
  const LoadResult r = parseEffect(text, "fx.toml", {});
  for (const Diagnostic& d : r.diagnostics) ADD_FAILURE() << d.format();
  return r.ok() ? *r.effect : EffectSettings{};
}

std::vector<std::string> errors(const std::string& text) {
  const LoadResult r = parseEffect(text, "fx.toml", {});
  std::vector<std::string> out;
  for (const Diagnostic& d : r.diagnostics) out.push_back(d.format());
  EXPECT_FALSE(r.ok());
  return out;
}

TEST(ioSubEmitters, EveryKeyIsRead) {
  const EffectSettings e = load(std::string(kHead) + kFireworks);
  ASSERT_EQ(e.emitters.size(), 2u);
  const EmitterSettings& s = e.emitters[1];
  EXPECT_EQ(s.sub.parent, "shells");
  EXPECT_EQ(s.sub.on, EmitterEvent::Death);
  EXPECT_EQ(s.sub.countMin, 20u);
  EXPECT_EQ(s.sub.countMax, 30u);
  EXPECT_EQ(s.sub.inheritVelocity, 0.5);
  EXPECT_EQ(s.sub.inherit, std::vector<std::string>{"pscale"});
  // In order of name (a TOML table has no order): Alpha, Cd, heat.
  ASSERT_EQ(s.attributes.size(), 3u);
  EXPECT_EQ(s.attributes[0].name, "Alpha");
  EXPECT_EQ(s.attributes[1].name, "Cd");
  EXPECT_EQ(s.attributes[1].kind, LifeAttributeSettings::Kind::Ramp);
  EXPECT_EQ(s.attributes[1].interpolation, RampInterpolation::Smooth);
  EXPECT_EQ(s.attributes[1].keys[1].value[0], 0.3f);
  EXPECT_EQ(s.attributes[2].kind, LifeAttributeSettings::Kind::Random);
  EXPECT_EQ(s.attributes[2].high[0], 900.0f);
  EXPECT_TRUE(lintEffect(e).empty());
}

TEST(ioSubEmitters, BadParentsCyclesAndValuesAreLocated) {
  EXPECT_EQ(errors(std::string(kHead) + R"([[emitters]]
name = "shells"
rate = 1.0
[[emitters]]
name = "sparks"
parent = "shels"
on = "death"
)"),
            (std::vector<std::string>{
                "fx.toml:10:10: error: emitters.1.parent: \"shels\" is not the name of an "
                "emitter; did you mean \"shells\"? (expected the name of another [[emitters]] "
                "entry)"}));
  EXPECT_EQ(errors(std::string(kHead) + R"([[emitters]]
name = "a"
parent = "b"
on = "birth"
[[emitters]]
name = "b"
parent = "a"
on = "death"
)"),
            (std::vector<std::string>{
                "fx.toml:7:10: error: emitters.0.parent: \"a\" -> \"b\" -> \"a\" is a cycle of "
                "parents (expected a chain of parents ending at an emitter that has none)",
                "fx.toml:11:10: error: emitters.1.parent: \"b\" -> \"a\" -> \"b\" is a cycle of "
                "parents (expected a chain of parents ending at an emitter that has none)"}));
  EXPECT_EQ(errors(std::string(kHead) + R"([[emitters]]
name = "shells"
rate = 1.0
[emitters.attributes]
Cd = { ramp = [[0.5, [1.0, 1.0, 1.0]], [0.25, [1.0, 0.0, 0.0]]] }
Alpha = { ramp = [[0.0, 1.0], [1.5, 0.0]] }
pscale = -0.1
)"),
            (std::vector<std::string>{
                "fx.toml:9:40: error: emitters.0.attributes.Cd.ramp.1: nage 0.25 is not after "
                "the previous key's 0.5 (expected keys in rising order of nage)",
                "fx.toml:10:31: error: emitters.0.attributes.Alpha.ramp.1: nage 1.5 is out of "
                "range (expected nage (age / lifetime) from 0 to 1)",
                "fx.toml:11:10: error: emitters.0.attributes.pscale: -0.1 is out of "
                "range (expected a radius in metres, >= 0)"}));
  EXPECT_EQ(errors(std::string(kHead) + R"([[emitters]]
name = "shells"
rate = 1.0
on = "death"
attributes = { Cd = [1.0, -2.0, 0.0] }
)"),
            (std::vector<std::string>{
                "fx.toml:8:1: error: emitters.0.on: applies to a sub-emitter only (expected "
                "parent = \"NAME\" with it)"}));
}

TEST(ioSubEmitters, CollisionEventsWithoutCollidersAreWarnedAbout) {
  const EffectSettings e = load(std::string(kHead) + R"([[emitters]]
name = "drops"
rate = 10.0
[[emitters]]
name = "splashes"
parent = "drops"
on = "collision"
direction = "normal"
)");
  const std::vector<Diagnostic> w = lintEffect(e);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_EQ(w[0].format(),
            "fx.toml:11:6: warning: emitters.1.on: the effect has no [[colliders]]: \"drops\" "
            "never collides, and \"splashes\" never emits");
}

class ioSubEmittersOnDisk : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("tickfx_sub_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::filesystem::path dir_;
};

// Colour, opacity and size in every format under the names each reads: VDB Cd as a vec3s colour,
// Alpha and pscale floats; PLY red, green, blue, alpha; CSV Cd_r, Cd_g, Cd_b. Each reads back the
// captured frame bit for bit.
TEST_F(ioSubEmittersOnDisk, ColourOpacityAndSizeGoToEveryCacheFormat) {
  const auto system = buildSystem(load(std::string(kHead) + kFireworks));
  system->stepTicks(45);
  const FrameData frame = captureFrame(*system, 18, 0.75);
  EXPECT_EQ(frame.attributeNames, (std::vector<std::string>{"emitter", "pscale", "Alpha", "Cd_r",
                                                            "Cd_g", "Cd_b", "heat"}));
  ASSERT_GT(frame.size(), 80u);
  for (std::size_t i = 0; i < frame.size(); ++i) {
    const auto r = static_cast<Eigen::Index>(i);
    EXPECT_EQ(frame.attributes[0][r], 1.0f) << "every shell has burst";
    EXPECT_EQ(frame.attributes[1][r], 0.1f) << "inherited from the shell";
    EXPECT_GE(frame.attributes[6][r], 700.0f);
    EXPECT_LT(frame.attributes[6][r], 900.0f);
    // Alpha falls linearly from 1 to 0 over life.
    const float nage = normalisedAge(frame.age[r], frame.life[r]);
    EXPECT_EQ(frame.attributes[2][r], 1.0f + (0.0f - 1.0f) * nage);
  }
  writeCsvCache(frame, dir_ / "f.csv");
  writePlyCache(frame, dir_ / "f.ply");
  writeVdbPointCache(frame, VdbCacheMetadata{}, dir_ / "f.vdb");
  EXPECT_EQ(frameHash(readCsvCache(dir_ / "f.csv")), frameHash(frame));
  EXPECT_EQ(frameHash(readPlyCache(dir_ / "f.ply")), frameHash(frame));
  EXPECT_EQ(frameHash(readVdbPointCache(dir_ / "f.vdb")), frameHash(frame));

  const std::string head = test::fileBytes(dir_ / "f.ply");
  EXPECT_NE(head.find("property int emitter\nproperty float pscale\nproperty float alpha\n"
                      "property float red\nproperty float green\nproperty float blue\n"
                      "property float heat\nend_header\n"),
            std::string::npos);
  const vdb_test::PointsGridRead grid = vdb_test::readPointsGrid(dir_ / "f.vdb", "points");
  ASSERT_FALSE(grid.leaves.empty());
  std::map<std::string, std::string> types = vdb_test::attributeTypes(grid.leaves.front());
  for (const auto& [name, type] : std::vector<std::pair<std::string, std::string>>{
           {"Cd", "vec3s"}, {"Alpha", "float"}, {"pscale", "float"}, {"emitter", "int32"}}) {
    ASSERT_TRUE(types.count(name)) << name;
    EXPECT_EQ(types[name], type) << name;
  }
}

// A checkpoint written after the shells died and before their sparks are born (the events wait)
// resumes to the uninterrupted run's hash.
TEST_F(ioSubEmittersOnDisk, ACheckpointBetweenADeathAndItsChildrenResumesExactly) {
  const EffectSettings effect = load(std::string(kHead) + kFireworks);
  const auto whole = buildSystem(effect);
  whole->stepTicks(30);
  ASSERT_EQ(whole->pool().size(), 0u);
  ASSERT_EQ(whole->events()->pending().size(), 4u);
  writeCheckpoint(dir_ / "c.ckpt", *whole, CheckpointInfo{7, 0, 0});
  whole->stepTicks(40);
  const auto resumed = buildSystem(effect);
  readCheckpoint(dir_ / "c.ckpt", *resumed, 7);
  EXPECT_EQ(resumed->events()->pending().size(), 4u);
  resumed->stepTicks(40);
  EXPECT_GT(resumed->pool().size(), 80u);
  EXPECT_EQ(hashToHex(stateHash(*resumed)), hashToHex(stateHash(*whole)));
  // The same checkpoint into an effect without sub-emitters is refused by name.
  const auto plain = buildSystem(load(std::string(kHead) + R"([[emitters]]
name = "shells"
bursts = [{time = 0.0, count = 4}]
)"));
  try {
    readCheckpoint(dir_ / "c.ckpt", *plain, 7);
    ADD_FAILURE() << "read";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()),
              (dir_ / "c.ckpt").string() +
                  ": error: checkpoint has particle attributes [emitter, pscale] (expected [])");
  }
}

}  // namespace
}  // namespace tickfx::io
