// Every sample effect reaches the state recorded in tests/data/golden_hashes.txt after 2 s of
// ticks: a change that moves the bits of any sample's state is caught, and must be made on purpose.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "io/EffectBuilder.h"
#include "io/EffectParser.h"
#include "particles/StateHash.h"
#include "particles/TaskExecutor.h"
#include "tests/WorkerPool.h"

namespace tickfx::io {
namespace {

const std::filesystem::path kSourceDir = TICKFX_SOURCE_DIR;
const std::filesystem::path kGoldenFile = kSourceDir / "tests" / "data" / "golden_hashes.txt";

struct GoldenHash {
  std::string file;  // in samples/
  std::string hash;  // 16 lowercase hex digits
  int line = 0;
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

GoldenList readGoldenList() {
  GoldenList list;
  std::ifstream in(kGoldenFile);
  if (!in) {
    list.errors.push_back(kGoldenFile.string() + ": cannot be read");
    return list;
  }
  std::string text;
  for (int number = 1; std::getline(in, text); ++number) {
    std::istringstream fields(text);
    GoldenHash entry{.file = {}, .hash = {}, .line = number};
    if (!(fields >> entry.file) || entry.file[0] == '#') continue;
    std::string extra;
    if (!(fields >> entry.hash) || fields >> extra || !isHashText(entry.hash)) {
      list.errors.push_back(kGoldenFile.string() + ":" + std::to_string(number) +
                            ": expected `<sample file> <16 lowercase hex digits>`, got `" + text +
                            "`");
      continue;
    }
    list.entries.push_back(entry);
  }
  return list;
}

// Read once, when the parameterised cases are generated, so each sample is its own ctest test.
const GoldenList& goldenList() {
  static const GoldenList list = readGoldenList();
  return list;
}

TEST(goldenHashesFile, IsWellFormed) {
  for (const std::string& error : goldenList().errors) ADD_FAILURE() << error;
  EXPECT_FALSE(goldenList().entries.empty()) << kGoldenFile.string() << ": no hashes";
}

// A sample without a golden hash would escape the cross-build checks unnoticed.
TEST(goldenHashesFile, ListsEverySampleOnce) {
  std::vector<std::string> found;
  for (const auto& entry : std::filesystem::directory_iterator(kSourceDir / "samples")) {
    if (entry.path().extension() == ".toml") found.push_back(entry.path().filename().string());
  }
  std::sort(found.begin(), found.end());
  std::vector<std::string> listed;
  for (const GoldenHash& g : goldenList().entries) listed.push_back(g.file);
  std::sort(listed.begin(), listed.end());
  EXPECT_EQ(std::adjacent_find(listed.begin(), listed.end()), listed.end())
      << kGoldenFile.string() << " lists a sample twice";
  for (const std::string& file : found) {
    EXPECT_TRUE(std::binary_search(listed.begin(), listed.end(), file))
        << "samples/" << file << " has no golden hash in " << kGoldenFile.string()
        << ": add its line (see the file's header for how it is produced)";
  }
  for (const std::string& file : listed) {
    EXPECT_TRUE(std::binary_search(found.begin(), found.end(), file))
        << kGoldenFile.string() << " lists " << file << ", which is not in samples/";
  }
}

// The parameter is the file name alone, so that ctest's test names do not change with the hashes.
std::vector<std::string> listedFiles() {
  std::vector<std::string> files;
  for (const GoldenHash& g : goldenList().entries) files.push_back(g.file);
  return files;
}

class goldenHashes : public ::testing::TestWithParam<std::string> {};

TEST_P(goldenHashes, StateAfterTwoSecondsOfTicks) {
  const auto& entries = goldenList().entries;
  const auto found = std::find_if(entries.begin(), entries.end(),
                                  [&](const GoldenHash& g) { return g.file == GetParam(); });
  ASSERT_NE(found, entries.end());
  const GoldenHash& golden = *found;
  const std::filesystem::path path = kSourceDir / "samples" / golden.file;
  const LoadResult load = loadEffectFile(path);
  for (const Diagnostic& d : load.diagnostics) ADD_FAILURE() << d.format();
  ASSERT_TRUE(load.ok());
  const std::unique_ptr<ParticleSystem> system = buildSystem(*load.effect);
  const std::int64_t ticks = 2 * load.effect->simulation.stepRateHz;
  system->stepTicks(ticks);
  ASSERT_EQ(system->tickCount(), ticks);
  const std::string actual = hashToHex(stateHash(system->pool()));
  EXPECT_EQ(actual, golden.hash)
      << "samples/" << golden.file << ": the state after " << ticks << " ticks changed.\n"
      << "  new line: " << golden.file << " " << actual << "\n"
      << "If the change of results is intended, replace line " << golden.line << " of "
      << kGoldenFile.string()
      << " with the new line, on purpose, and give the reason in the commit message. If not, a "
         "change has moved the bits of the state: find it.";
}

// A host that runs tickfx's loops on its own job system gets the same bits: on the calling thread
// alone, and on four workers of its own that take the blocks in any order.
TEST_P(goldenHashes, SameStateOnHostExecutors) {
  const auto& entries = goldenList().entries;
  const auto found = std::find_if(entries.begin(), entries.end(),
                                  [&](const GoldenHash& g) { return g.file == GetParam(); });
  ASSERT_NE(found, entries.end());
  const LoadResult load = loadEffectFile(kSourceDir / "samples" / found->file);
  ASSERT_TRUE(load.ok());
  const std::int64_t ticks = 2 * load.effect->simulation.stepRateHz;
  SerialExecutor serial;
  WorkerPool workers(4);
  for (TaskExecutor* executor : std::vector<TaskExecutor*>{&serial, &workers}) {
    const std::unique_ptr<ParticleSystem> system = buildSystem(*load.effect);
    system->setTaskExecutor(executor);
    system->stepTicks(ticks);
    EXPECT_EQ(hashToHex(stateHash(system->pool())), found->hash)
        << (executor == &serial ? "serial executor" : "4 workers");
  }
}

INSTANTIATE_TEST_SUITE_P(Samples, goldenHashes, ::testing::ValuesIn(listedFiles()),
                         [](const ::testing::TestParamInfo<std::string>& entry) {
                           const std::string& file = entry.param;
                           std::string name = file.substr(0, file.rfind('.'));
                           for (char& c : name) {
                             const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') ||
                                             (c >= '0' && c <= '9');
                             if (!ok) c = '_';
                           }
                           return name;
                         });
// A missing or empty list is reported by goldenHashesFile.IsWellFormed, not as a setup error.
GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(goldenHashes);

}  // namespace
}  // namespace tickfx::io
