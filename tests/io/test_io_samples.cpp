// Every samples/*.toml loads without errors, lints as documented, builds and runs.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "io/effect/EffectBuilder.h"
#include "io/effect/EffectLint.h"
#include "io/effect/EffectParser.h"

namespace tickfx::io {
namespace {

const std::vector<std::string> kSamples = {
    "fountain",   "oscillator",     "wind_aliasing", "wind_aliasing_fixed", "smoke_drift", "burst",
    "rope_swing", "flag",           "jelly",         "vortex_smoke",        "leaves",      "rain",
    "drum",       "sand_on_sphere", "fireworks",     "sparks_grind"};

std::filesystem::path samplePath(const std::string& name) {
  return std::filesystem::path(TICKFX_SOURCE_DIR) / "samples" / (name + ".toml");
}

EffectSettings loadSample(const std::string& name) {
  const LoadResult result = loadEffectFile(samplePath(name));
  for (const Diagnostic& d : result.diagnostics) ADD_FAILURE() << d.format();
  return result.ok() ? *result.effect : EffectSettings{};
}

class ioSamples : public ::testing::TestWithParam<std::string> {};

TEST_P(ioSamples, LoadsBuildsAndRuns) {
  const EffectSettings effect = loadSample(GetParam());
  ASSERT_FALSE(effect.emitters.empty() && effect.structures.empty());
  const std::vector<Diagnostic> warnings = lintEffect(effect);
  if (GetParam() == "wind_aliasing") {
    ASSERT_EQ(warnings.size(), 1u);
    EXPECT_EQ(
        warnings[0].format(),
        samplePath("wind_aliasing").string() +
            ":24:13: warning: forces.0.frequency: 16 Hz wind is above the Nyquist limit of 10 "
            "Hz (half of step_rate = 20 Hz) and is sampled as a 4 Hz wind (use a step_rate of "
            "at least 33 Hz)");
  } else {
    for (const Diagnostic& d : warnings) ADD_FAILURE() << d.format();
  }
  const std::unique_ptr<ParticleSystem> system = buildSystem(effect, 2);
  // A few frames through the driver, as a player would.
  const Flicks frame = frameDuration(effect.output.fps);
  std::int64_t ticks = 0;
  for (int f = 0; f < 5; ++f) ticks += system->advance(frame).ticks;
  EXPECT_EQ(system->tickCount(), ticks);
  EXPECT_GT(ticks, 0);
  EXPECT_GE(effect.output.frameCount(), 1);
}

INSTANTIATE_TEST_SUITE_P(Samples, ioSamples, ::testing::ValuesIn(kSamples),
                         [](const ::testing::TestParamInfo<std::string>& sample) {
                           return sample.param;
                         });

TEST(ioSamplesList, EverySampleFileIsTested) {
  std::vector<std::string> found;
  for (const auto& entry : std::filesystem::directory_iterator(TICKFX_SOURCE_DIR "/samples")) {
    if (entry.path().extension() == ".toml") found.push_back(entry.path().stem().string());
  }
  std::sort(found.begin(), found.end());
  std::vector<std::string> listed = kSamples;
  std::sort(listed.begin(), listed.end());
  EXPECT_EQ(found, listed);
}

TEST(ioSamplesList, AliasedWindDriftsTheWrongWay) {
  // wind_aliasing.toml against its corrected twin: after one second the leaves' mean x is
  // negative at 20 Hz (the 16 Hz sine sampled as a −4 Hz one) and positive at 240 Hz.
  const auto meanX = [](const std::string& name) {
    const std::unique_ptr<ParticleSystem> system = buildSystem(loadSample(name), 1);
    system->stepTicks(system->settings().stepRateHz);
    const auto n = static_cast<Eigen::Index>(system->pool().size());
    return system->pool().position().x.head(n).mean();
  };
  EXPECT_LT(meanX("wind_aliasing"), -0.5f);
  EXPECT_GT(meanX("wind_aliasing_fixed"), 0.5f);
}

TEST(ioSamplesList, DocumentationExampleIsValid) {
  // The complete example of docs/effects.md (its first toml block) loads, lints clean and runs.
  std::ifstream in(TICKFX_SOURCE_DIR "/docs/effects.md");
  std::stringstream text;
  text << in.rdbuf();
  const std::string doc = text.str();
  const std::size_t begin = doc.find("```toml\n");
  ASSERT_NE(begin, std::string::npos);
  const std::size_t end = doc.find("```", begin + 8);
  ASSERT_NE(end, std::string::npos);
  const LoadResult result = parseEffect(doc.substr(begin + 8, end - begin - 8), "effects.md");
  for (const Diagnostic& d : result.diagnostics) ADD_FAILURE() << d.format();
  ASSERT_TRUE(result.ok());
  EXPECT_EQ(result.effect->forces.size(), 4u);
  for (const Diagnostic& d : lintEffect(*result.effect)) ADD_FAILURE() << d.format();
  buildSystem(*result.effect, 1)->stepTicks(10);
}

}  // namespace
}  // namespace tickfx::io
