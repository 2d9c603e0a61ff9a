// USD points in the text format: frames written by UsdaPointsWriter read back bit for bit by the
// grammar's parser (io/cache/UsdaReader), values no run avoids (nan, inf, empty frames, many
// points), the layer's metadata as USD tools read it, and files cut short refused by name.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include "Sanitized.h"
#include "io/cache/UsdaPointsWriter.h"
#include "io/cache/UsdaReader.h"
#include "tests/support/FileBytes.h"

namespace tickfx::io {
namespace {

class Usda : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("tickfx_usda_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  std::filesystem::path dir_;
};

// A frame of `n` points whose values run through what a careless text format would change.
FrameData frameOf(std::int64_t number, std::size_t n) {
  FrameData f;
  f.frame = number;
  f.resize(n, {"emitter", "pscale", "Alpha", "Cd_r", "Cd_g", "Cd_b", "hitpos_x", "hitpos_y",
               "hitpos_z", "heat"});
  const float special[] = {0.0f,
                           -0.0f,
                           std::numeric_limits<float>::infinity(),
                           -std::numeric_limits<float>::infinity(),
                           std::numeric_limits<float>::quiet_NaN(),
                           1e-45f,
                           -1e-40f,
                           std::numeric_limits<float>::max(),
                           0.1f,
                           1.0f / 3.0f};
  for (std::size_t i = 0; i < n; ++i) {
    const auto r = static_cast<Eigen::Index>(i);
    const auto k = static_cast<float>(i) + static_cast<float>(number);
    f.id[i] = (std::uint64_t{1} << 40) + 3 * i + static_cast<std::uint64_t>(number);
    for (int c = 0; c < 3; ++c) {
      f.position[c][r] = special[(i + static_cast<std::size_t>(c)) % 10] * (c == 1 ? k : 1.0f);
      f.velocity[c][r] = k * 0.37f - static_cast<float>(c);
    }
    f.age[r] = k / 7.0f;
    f.life[r] = i % 2 == 0 ? std::numeric_limits<float>::infinity() : 3.5f;
    f.mass[r] = 1e-4f * k;
    f.attributes[0][r] = i % 3 == 0 ? -1.0f : static_cast<float>(i % 3);  // emitter, an int
    f.attributes[1][r] = 0.01f * k;
    f.attributes[2][r] = 1.0f - 0.01f * k;
    for (int c = 0; c < 3; ++c) {
      f.attributes[3 + static_cast<std::size_t>(c)][r] = 0.25f * static_cast<float>(c) + 1e-3f * k;
      f.attributes[6 + static_cast<std::size_t>(c)][r] = special[(i + 5) % 10];
    }
    f.attributes[9][r] = 700.0f + k;
  }
  return f;
}

TEST_F(Usda, FramesReadBackBitForBitWithAChangingCount) {
  const std::filesystem::path file = dir_ / "run.usda";
  {
    UsdaPointsWriter w(file, UsdaLayerSettings{24.0, "particles"});
    w.write(frameOf(1, 12));
    w.write(frameOf(2, 0));  // an empty frame
    w.write(frameOf(3, 25));
    EXPECT_FALSE(std::filesystem::exists(file)) << "nothing before finish()";
    w.finish();
  }
  EXPECT_FALSE(std::filesystem::exists(dir_ / "run.usda.parts")) << "the streams are removed";
  EXPECT_EQ(usdaFrames(file), (std::vector<std::int64_t>{1, 2, 3}));
  for (const auto& [number, n] : {std::pair{1, 12}, std::pair{2, 0}, std::pair{3, 25}}) {
    const FrameData read = readUsdaFrame(file, number);
    const FrameData expected = frameOf(number, static_cast<std::size_t>(n));
    EXPECT_EQ(read.attributeNames, expected.attributeNames);
    EXPECT_EQ(frameHash(read), frameHash(expected)) << "frame " << number;
    EXPECT_EQ(read.timeSeconds, static_cast<double>(number) / 24.0);
  }
}

TEST_F(Usda, TheLayerSaysWhatUsdToolsRead) {
  const std::filesystem::path file = dir_ / "run.usda";
  UsdaPointsWriter w(file, UsdaLayerSettings{30000.0 / 1001.0, "particles"});
  w.write(frameOf(4, 6));
  w.write(frameOf(5, 1));
  w.finish();
  const std::string t = test::fileBytes(file);
  const std::string head =
      "#usda 1.0\n(\n    defaultPrim = \"particles\"\n    endTimeCode = 5\n"
      "    metersPerUnit = 1\n    startTimeCode = 4\n"
      "    timeCodesPerSecond = 29.97002997002997\n    upAxis = \"Y\"\n)\n\n"
      "def Points \"particles\"\n{\n    point3f[] points.timeSamples = {\n";
  EXPECT_EQ(t.substr(0, head.size()), head);
  for (const char* line :
       {"    vector3f[] velocities.timeSamples = {\n", "    int64[] ids.timeSamples = {\n",
        "        5: [1099511627781],\n", "    float[] widths.timeSamples = {\n",
        "    color3f[] primvars:displayColor (\n        interpolation = \"vertex\"\n    )\n",
        "    float[] primvars:displayOpacity.timeSamples = {\n",
        "    int[] primvars:emitter.timeSamples = {\n        4: [-1, 1, 2, -1, 1, 2],\n",
        "    vector3f[] primvars:hitpos.timeSamples = {\n", "    float[] primvars:age (\n",
        "        4: [(0, -0, inf), (-0, inf, -inf), (inf, -inf, nan), "}) {
    EXPECT_NE(t.find(line), std::string::npos) << line;
  }
  EXPECT_NE(t.find("nan"), std::string::npos);
}

// The parser reads the grammar, not the writer's layout: comments, other spacing, metadata,
// defaults, other prims and attributes it does not know.
TEST_F(Usda, AnyLayoutOfTheGrammarReads) {
  const std::filesystem::path file = dir_ / "hand.usda";
  std::ofstream(file) << R"(#usda 1.0
( # the layer
    doc = """made by hand"""
    timeCodesPerSecond = 48
    customLayerData = { string creator = "test" }
)
def Xform "world" { double3 xformOp:translate = (1, 2, 3)
    uniform token[] xformOpOrder = ["xformOp:translate"]
    def Points "inner" { point3f[] points = [(9, 9, 9)] }
}
def Points "p" (kind = "component")
{
    rel material:binding = </world>
    point3f[] points.timeSamples = { 7 : [ ( 1.5 , -2 , 3e-3 ) , (4,5,6) ] , 8: [] }
    vector3f[] velocities.timeSamples={7:[(0,0,0),(1,1,1)],8:[]}
    int64[] ids.timeSamples = {
        7: [10, 11],
        8: [],
    }
    float[] primvars:age = [0.5, 0.5]
    float[] primvars:age.timeSamples = { 7: [0.25, +0.5], 8: [] }
    float[] primvars:life.timeSamples = { 7: [inf, 1], 8: [] }
    float[] primvars:mass.timeSamples = { 7: [1, 2], 8: [] }
    float[] widths ( interpolation = "vertex" ; )
    float[] widths.timeSamples = { 7: [0.5, 1e-44], 8: [] }
}
)";
  const FrameData f = readUsdaFrame(file, 7);
  ASSERT_EQ(f.size(), 2u);
  EXPECT_EQ(f.id, (UninitialisedVector<std::uint64_t>{10, 11}));
  EXPECT_EQ(f.position.x[0], 1.5f);
  EXPECT_EQ(f.position.z[0], 3e-3f);
  EXPECT_EQ(f.age[1], 0.5f);
  EXPECT_TRUE(std::isinf(f.life[0]));
  EXPECT_EQ(f.attributeNames, std::vector<std::string>{"pscale"});
  EXPECT_EQ(f.attributes[0][0], 0.25f);
  EXPECT_EQ(f.attributes[0][1], 5e-45f);  // a subnormal diameter halved exactly
  EXPECT_EQ(f.timeSeconds, 7.0 / 48.0);
  EXPECT_EQ(readUsdaFrame(file, 8).size(), 0u);
  EXPECT_EQ(usdaFrames(file), (std::vector<std::int64_t>{7, 8}));
}

TEST_F(Usda, FilesCutShortOrOfAnotherKindAreRefusedByName) {
  const std::filesystem::path file = dir_ / "run.usda";
  UsdaPointsWriter w(file, UsdaLayerSettings{});
  w.write(frameOf(1, 30));
  w.finish();
  const std::string whole = test::fileBytes(file);
  const std::filesystem::path cut = dir_ / "cut.usda";
  for (const std::size_t at : {whole.size() / 3, whole.size() / 2, whole.size() - 3}) {
    std::ofstream(cut, std::ios::binary) << whole.substr(0, at);
    try {
      readUsdaFrame(cut, 1);
      ADD_FAILURE() << "read a file cut at byte " << at;
    } catch (const std::runtime_error& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind(cut.string() + ": ", 0), 0u) << what;
      EXPECT_NE(what.find("cut short"), std::string::npos) << what;
    }
  }
  std::ofstream(cut, std::ios::binary) << "ply\nformat ascii 1.0\n";
  try {
    readUsdaFrame(cut, 1);
    ADD_FAILURE() << "read a PLY file";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()),
              cut.string() + ": is not a USD text layer (it does not start with '#usda 1.0')");
  }
  try {
    readUsdaFrame(file, 2);
    ADD_FAILURE() << "read a frame the layer does not have";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), file.string() + ": has no ids at frame 2");
  }
}

TEST_F(Usda, AMillionPointsWriteAndReadBack) {
  const std::size_t n = test::kSanitized ? 100'000 : 1'000'000;
  const std::filesystem::path file = dir_ / "big.usda";
  UsdaPointsWriter w(file, UsdaLayerSettings{});
  const FrameData frame = frameOf(1, n);
  w.write(frame);
  w.finish();
  EXPECT_EQ(frameHash(readUsdaFrame(file, 1)), frameHash(frame));
}

}  // namespace
}  // namespace tickfx::io
