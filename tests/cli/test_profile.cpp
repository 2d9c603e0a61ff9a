// `tickfx run --profile`: the phases of a run as the table prints them, adding up to the run's
// wall time, the process's own life as the test measured it.
#include <gtest/gtest.h>

#include <chrono>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <string_view>

#include "CliTestSupport.h"
#include "Sanitized.h"

namespace {

using tickfx::cli_test::Result;

class Profile : public tickfx::cli_test::CliFixture {
 protected:
  Profile() : CliFixture("tickfx_profile") {}
};

struct Row {
  double wall = 0.0, share = 0.0, serial = 0.0, serialShare = 0.0;
};

// The table's rows by phase name ("total" too); the title's wall time in `wall`.
std::map<std::string, Row> parseProfile(const std::string& out, double& wall) {
  std::map<std::string, Row> rows;
  std::smatch m;
  if (std::regex_search(out, m, std::regex(R"(profile: ([0-9.]+) s wall on (\d+) threads?\n)")))
    wall = std::stod(m[1]);
  const std::regex row(R"(\n  ([a-z ]+?) +([0-9.]+) +([0-9.]+) % +(-?[0-9.]+) +(-?[0-9.]+) %)");
  for (auto it = std::sregex_iterator(out.begin(), out.end(), row); it != std::sregex_iterator();
       ++it) {
    rows[(*it)[1]] = {std::stod((*it)[2]), std::stod((*it)[3]), std::stod((*it)[4]),
                      std::stod((*it)[5])};
  }
  return rows;
}

// A burst of 400 000 particles with lives of 0.2 to 0.6 s, a stream after it, PLY caches: every
// phase of a frame has work.
constexpr const char* kEffect = R"(format_version = 1
[simulation]
step_rate = 120
seed = 3
max_particles = 1000000
threads = 2
[[emitters]]
name = "burst"
shape = "box"
size = [10.0, 10.0, 10.0]
rate = 100000.0
bursts = [{ time = 0.0, count = 400000 }]
direction = [0.0, 1.0, 0.0]
speed = 4.0
spread = 30.0
lifetime = 0.4
lifetime_jitter = 0.5
[[forces]]
type = "gravity"
[output]
fps = 24
seconds = 1.0
formats = ["ply"]
directory = "unused"
)";

TEST_F(Profile, ThePhasesAddUpToTheRunsWallTime) {
  const std::string effect = writeFile("burst.toml", kEffect);
  const auto start = std::chrono::steady_clock::now();
  const Result r = runProgram(TICKFX_CLI, "run " + effect + " --profile --quiet --out " +
                                              path("caches") + " --checkpoint-every 12");
  const double measured =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_EQ(r.exit, 0) << r.err;
  double wall = 0.0;
  const std::map<std::string, Row> rows = parseProfile(r.out, wall);
  ASSERT_GT(wall, 0.0) << r.out;
  ASSERT_EQ(rows.count("total"), 1u) << r.out;
  double sum = 0.0;
  for (const char* phase : {"startup", "load", "growth", "emission", "step", "deaths", "capture",
                            "checkpoint", "cache write", "release"}) {
    ASSERT_EQ(rows.count(phase), 1u) << phase << " missing from\n" << r.out;
    // Freeing this run's 20 MB, and loading its effect of twenty lines, may take under the half
    // millisecond a row rounds to (both have: CI73 printed 0.000 s for the load).
    if (std::string_view(phase) != "release" && std::string_view(phase) != "load") {
      EXPECT_GT(rows.at(phase).wall, 0.0) << phase;
    }
    EXPECT_GE(rows.at(phase).serialShare, 0.0) << phase;
    EXPECT_LE(rows.at(phase).serialShare, 100.0) << phase;
  }
  for (const auto& [name, row] : rows) {
    if (name != "total") sum += row.wall;
  }
  // Each row is rounded to the millisecond.
  EXPECT_NEAR(sum, wall, 0.02 * wall) << r.out;
  EXPECT_EQ(rows.at("total").wall, wall);
  // The ticks run in parallel blocks: most of the step phase is parallel.
  EXPECT_LT(rows.at("step").serialShare, 50.0) << r.out;
  // The process lived `measured` seconds from the test's side: the profile covers all of it but
  // the shell that started it, its exit after the table, and the 10 ms granularity of the
  // kernel's start time (50 ms in all, at most). Sanitizer builds spend long at exit (leak checks).
  // That start time is truncated to its 10 ms tick, so the profile may count up to 10 ms the
  // process did not live (and it rounds to the millisecond).
  EXPECT_LE(wall, measured + 0.011) << r.out;
  if (!tickfx::test::kSanitized) {
    EXPECT_GE(wall, 0.98 * measured - 0.05) << r.out;
  }
}

TEST_F(Profile, WithoutTheFlagNothingIsPrinted) {
  const std::string effect = writeFile("burst.toml", kEffect);
  const Result r = runProgram(TICKFX_CLI, "run " + effect + " --quiet --format none --seconds 0.1");
  ASSERT_EQ(r.exit, 0) << r.err;
  EXPECT_EQ(r.out, "");
}

}  // namespace
