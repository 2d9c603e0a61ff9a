// Every sample effect, and every golden effect of tests/data/golden/, reaches the state recorded
// for it (tests/data/golden_hashes.txt, tests/data/golden/hashes.txt) after 2 s of ticks: a change
// that moves the bits of any of their states is caught, and must be made on purpose.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "WorkerPool.h"
#include "io/effect/EffectBuilder.h"
#include "io/effect/EffectParser.h"
#include "particles/StateHash.h"
#include "particles/TaskExecutor.h"

namespace tickfx::io {
namespace {

const std::filesystem::path kSourceDir = TICKFX_SOURCE_DIR;

// A list of golden hashes and the folder of the effects it names.
struct GoldenSource {
  std::filesystem::path list;
  std::filesystem::path folder;  // relative to the source tree
};

const GoldenSource kSamples{kSourceDir / "tests" / "data" / "golden_hashes.txt", "samples"};
const GoldenSource kGoldenEffects{kSourceDir / "tests" / "data" / "golden" / "hashes.txt",
                                  std::filesystem::path("tests") / "data" / "golden"};

struct GoldenHash {
  std::string file;  // in the source's folder
  std::string hash;  // 16 lowercase hex digits
  int line = 0;
  const GoldenSource* source = nullptr;
  /// The effect, relative to the source tree: the test's parameter.
  std::string relativePath() const { return (source->folder / file).generic_string(); }
};

struct GoldenList {
  std::vector<GoldenHash> entries;
  std::vector<std::string> errors;
};

bool isHashText(const std::string& text) {
  return text.size() == 16 && std::all_of(text.begin(), text.end(), [](char c) {
           return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f');
         });
}

GoldenList readGoldenList(const GoldenSource& source) {
  GoldenList list;
  std::ifstream in(source.list);
  if (!in) {
    list.errors.push_back(source.list.string() + ": cannot be read");
    return list;
  }
  std::string text;
  for (int number = 1; std::getline(in, text); ++number) {
    std::istringstream fields(text);
    GoldenHash entry{.file = {}, .hash = {}, .line = number, .source = &source};
    if (!(fields >> entry.file) || entry.file[0] == '#') continue;
    std::string extra;
    if (!(fields >> entry.hash) || fields >> extra || !isHashText(entry.hash)) {
      list.errors.push_back(source.list.string() + ":" + std::to_string(number) +
                            ": expected `<effect file> <16 lowercase hex digits>`, got `" + text +
                            "`");
      continue;
    }
    list.entries.push_back(entry);
  }
  return list;
}

// Read once, when the parameterised cases are generated, so each effect is its own ctest test.
const GoldenList& goldenList(const GoldenSource& source) {
  static const GoldenList samples = readGoldenList(kSamples);
  static const GoldenList effects = readGoldenList(kGoldenEffects);
  return &source == &kSamples ? samples : effects;
}

TEST(goldenHashesFile, IsWellFormed) {
  for (const GoldenSource* source : {&kSamples, &kGoldenEffects}) {
    for (const std::string& error : goldenList(*source).errors) ADD_FAILURE() << error;
    EXPECT_FALSE(goldenList(*source).entries.empty()) << source->list.string() << ": no hashes";
  }
}

// An effect without a golden hash would escape the cross-build checks unnoticed.
void expectListsEveryEffectOnce(const GoldenSource& source) {
  std::vector<std::string> found;
  for (const auto& entry : std::filesystem::directory_iterator(kSourceDir / source.folder)) {
    if (entry.path().extension() == ".toml") found.push_back(entry.path().filename().string());
  }
  std::sort(found.begin(), found.end());
  std::vector<std::string> listed;
  for (const GoldenHash& g : goldenList(source).entries) listed.push_back(g.file);
  std::sort(listed.begin(), listed.end());
  EXPECT_EQ(std::adjacent_find(listed.begin(), listed.end()), listed.end())
      << source.list.string() << " lists an effect twice";
  for (const std::string& file : found) {
    EXPECT_TRUE(std::binary_search(listed.begin(), listed.end(), file))
        << source.folder.generic_string() << "/" << file << " has no golden hash in "
        << source.list.string() << ": add its line (see the file's header for how it is produced)";
  }
  for (const std::string& file : listed) {
    EXPECT_TRUE(std::binary_search(found.begin(), found.end(), file))
        << source.list.string() << " lists " << file << ", which is not in "
        << source.folder.generic_string() << "/";
  }
}

TEST(goldenHashesFile, ListsEverySampleOnce) { expectListsEveryEffectOnce(kSamples); }

TEST(goldenHashesFile, ListsEveryGoldenEffectOnce) { expectListsEveryEffectOnce(kGoldenEffects); }

// The parameter is the effect's path alone, so that ctest's test names (its file's stem) do not
// change with the hashes.
std::vector<std::string> listedFiles(const GoldenSource& source) {
  std::vector<std::string> files;
  for (const GoldenHash& g : goldenList(source).entries) files.push_back(g.relativePath());
  return files;
}

const GoldenHash* findGolden(const std::string& relativePath) {
  for (const GoldenSource* source : {&kSamples, &kGoldenEffects}) {
    for (const GoldenHash& g : goldenList(*source).entries) {
      if (g.relativePath() == relativePath) return &g;
    }
  }
  return nullptr;
}

class goldenHashes : public ::testing::TestWithParam<std::string> {};

TEST_P(goldenHashes, StateAfterTwoSecondsOfTicks) {
  const GoldenHash* found = findGolden(GetParam());
  ASSERT_NE(found, nullptr);
  const GoldenHash& golden = *found;
  const std::filesystem::path path = kSourceDir / golden.relativePath();
  const LoadResult load = loadEffectFile(path);
  for (const Diagnostic& d : load.diagnostics) ADD_FAILURE() << d.format();
  ASSERT_TRUE(load.ok());
  const std::unique_ptr<ParticleSystem> system = buildSystem(*load.effect);
  const std::int64_t ticks = 2 * load.effect->simulation.stepRateHz;
  system->stepTicks(ticks);
  ASSERT_EQ(system->tickCount(), ticks);
  const std::string actual = hashToHex(stateHash(*system));
  EXPECT_EQ(actual, golden.hash)
      << golden.relativePath() << ": the state after " << ticks << " ticks changed.\n"
      << "  new line: " << golden.file << " " << actual << "\n"
      << "If the change of results is intended, replace line " << golden.line << " of "
      << golden.source->list.string()
      << " with the new line, on purpose, and give the reason in the commit message. If not, a "
         "change has moved the bits of the state: find it.";
}

// A host that runs tickfx's loops on its own job system gets the same bits: on the calling thread
// alone, and on four workers of its own that take the blocks in any order.
TEST_P(goldenHashes, SameStateOnHostExecutors) {
  const GoldenHash* found = findGolden(GetParam());
  ASSERT_NE(found, nullptr);
  const LoadResult load = loadEffectFile(kSourceDir / found->relativePath());
  ASSERT_TRUE(load.ok());
  const std::int64_t ticks = 2 * load.effect->simulation.stepRateHz;
  SerialExecutor serial;
  WorkerPool workers(4);
  for (TaskExecutor* executor : std::vector<TaskExecutor*>{&serial, &workers}) {
    const std::unique_ptr<ParticleSystem> system = buildSystem(*load.effect);
    system->setTaskExecutor(executor);
    system->stepTicks(ticks);
    EXPECT_EQ(hashToHex(stateHash(*system)), found->hash)
        << (executor == &serial ? "serial executor" : "4 workers");
  }
}

// Test names are the effects' stems: `Samples/goldenHashes.StateAfterTwoSecondsOfTicks/fountain`.
std::string stemName(const ::testing::TestParamInfo<std::string>& entry) {
  std::string name = std::filesystem::path(entry.param).stem().string();
  for (char& c : name) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9');
    if (!ok) c = '_';
  }
  return name;
}

INSTANTIATE_TEST_SUITE_P(Samples, goldenHashes, ::testing::ValuesIn(listedFiles(kSamples)),
                         stemName);
INSTANTIATE_TEST_SUITE_P(GoldenEffects, goldenHashes,
                         ::testing::ValuesIn(listedFiles(kGoldenEffects)), stemName);
// A missing or empty list is reported by goldenHashesFile.IsWellFormed, not as a setup error.
GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(goldenHashes);

}  // namespace
}  // namespace tickfx::io
