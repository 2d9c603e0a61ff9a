// The harness's paired figures (bench/BenchHarness.h): each round's two batches taken together,
// then the median over the rounds.
#include <gtest/gtest.h>

#include "BenchHarness.h"

namespace tickfx::bench {
namespace {

Case timed(const char* name, std::vector<double> secondsPerTick) {
  Case c(name, [](std::int64_t) {});
  c.secondsPerTick = std::move(secondsPerTick);
  return c;
}

// A load that moves between rounds moves both cases of a round alike: every round's ratio is 2.
TEST(BenchHarness, PairedSpeedupOfCasesThatKeepTheirRatio) {
  const Case baseline = timed("hand", {1.0, 8.0, 2.0, 16.0, 4.0});
  const Case fast = timed("step", {0.5, 4.0, 1.0, 8.0, 2.0});
  EXPECT_DOUBLE_EQ(pairedSpeedup(fast, baseline), 2.0);
  EXPECT_DOUBLE_EQ(pairedSpeedup(baseline, fast), 0.5);
}

// The median of the rounds' ratios (2, 1/2, 5/2), not the ratio of the medians (3 / 4).
TEST(BenchHarness, PairedSpeedupIsTheMedianOfTheRoundsRatios) {
  const Case baseline = timed("hand", {1.0, 3.0, 10.0});
  const Case c = timed("step", {0.5, 6.0, 4.0});
  EXPECT_DOUBLE_EQ(pairedSpeedup(c, baseline), 2.0);
  EXPECT_DOUBLE_EQ(speedup(c, baseline), 0.75);
}

TEST(BenchHarness, PairedFiguresTakeTheRoundsBothCasesHave) {
  const Case baseline = timed("hand", {1.0, 3.0, 100.0});
  const Case c = timed("step", {2.0, 1.0});
  EXPECT_DOUBLE_EQ(pairedSpeedup(c, baseline), 0.5 * (0.5 + 3.0));  // rounds 1/2 and 3
  EXPECT_DOUBLE_EQ(pairedShare(c, baseline), 0.5 * ((2.0 - 1.0) / 2.0 + (1.0 - 3.0) / 1.0));
  EXPECT_DOUBLE_EQ(pairedSpeedup(c, timed("none", {})), 0.0);
}

TEST(BenchHarness, PairedShareIsTheMedianOfEachRoundsShare) {
  const Case with = timed("with", {2.0, 10.0, 4.0});
  const Case without = timed("without", {1.5, 5.0, 3.0});  // shares 1/4, 1/2, 1/4
  EXPECT_DOUBLE_EQ(pairedShare(with, without), 0.25);
}

}  // namespace
}  // namespace tickfx::bench
