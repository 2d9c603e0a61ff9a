// The progress bar long commands draw on a terminal (app/ProgressLine): its text, and that it
// stays off when stderr is not a terminal.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdio>

#include "app/ProgressLine.h"

namespace tickfx::app {
namespace {

TEST(ProgressText, ShowsTheBarTheCountTheRateAndTheTimeLeft) {
  // A quarter of the frames in 2 s: 60 frames/s, 6 s left at that pace.
  EXPECT_EQ(progressText(120, 480, 0.25, 2.0, "frames", "t = 1.000 of 4.000 s"),
            "[=====>                  ] 120/480 frames  60.0 frames/s  6.0 s left  "
            "t = 1.000 of 4.000 s");
  // A count not known ahead (jittered frames), and long times left.
  EXPECT_EQ(progressText(7, -1, 0.01, 10.0, "frames", ""),
            "[                        ] 7 frames  0.7 frames/s  16 min 30 s left");
  EXPECT_EQ(progressText(1, 10, 0.001, 10.0, "schedules", "24 fps"),
            "[                        ] 1/10 schedules  0.1 schedules/s  2 h 46 min left  24 fps");
  // Done, and out-of-range fractions held to the bar.
  EXPECT_EQ(progressText(3, 3, 1.0, 1.5, "schedules", "8 threads"),
            "[========================] 3/3 schedules  2.0 schedules/s  0.0 s left  8 threads");
  EXPECT_EQ(progressText(0, 5, -2.0, 0.0, "frames", ""), "[                        ] 0/5 frames");
  EXPECT_EQ(progressText(5, 5, 7.0, 0.0, "frames", ""), "[========================] 5/5 frames");
}

TEST(ProgressLine, WritesNothingWhenStderrIsNotATerminal) {
  // stderr into a file: the line must stay off however long the work lasts.
  std::FILE* file = std::tmpfile();
  ASSERT_NE(file, nullptr);
  const int saved = ::dup(STDERR_FILENO);
  ASSERT_GE(saved, 0);
  std::fflush(stderr);
  ASSERT_GE(::dup2(::fileno(file), STDERR_FILENO), 0);
  {
    ProgressLine line("frames");
    ::usleep(1'100'000);  // past the second before the line may first show
    line.update(1, 2, 0.5, "half");
    line.finish();
  }
  std::fflush(stderr);
  ::dup2(saved, STDERR_FILENO);
  ::close(saved);
  EXPECT_EQ(std::ftell(file), 0L);
  std::fclose(file);
}

}  // namespace
}  // namespace tickfx::app
