// io::BackgroundWriter: frames written in the order handed over, at most two in memory, and the
// first failure stops it and reaches the caller.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <vector>

#include "io/cache/BackgroundWriter.h"
#include "io/cache/FrameData.h"

namespace tickfx::io {
namespace {

FrameData frameNumbered(std::int64_t f) {
  FrameData d;
  d.frame = f;
  return d;
}

// A write that waits until the test lets it go: the test sees what the caller can do meanwhile.
class Gate {
 public:
  void wait() {
    std::unique_lock lock(mutex_);
    ++waiting_;
    changed_.notify_all();
    changed_.wait(lock, [&] { return open_ > 0; });
    --open_;
  }
  void waitForWriter(int n) {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [&] { return waiting_ >= n; });
  }
  void letOneGo() {
    const std::lock_guard lock(mutex_);
    ++open_;
    changed_.notify_all();
  }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  int waiting_ = 0;
  int open_ = 0;
};

class ioBackgroundWriter : public ::testing::TestWithParam<bool> {};

TEST_P(ioBackgroundWriter, WritesEveryFrameInOrder) {
  std::vector<std::int64_t> written;
  BackgroundWriter writer([&](const FrameData& d) { written.push_back(d.frame); }, GetParam());
  for (std::int64_t f = 1; f <= 50; ++f) writer.submit(frameNumbered(f));
  writer.finish();
  ASSERT_EQ(written.size(), 50u);
  for (std::int64_t f = 1; f <= 50; ++f) EXPECT_EQ(written[static_cast<std::size_t>(f - 1)], f);
  EXPECT_EQ(writer.lastWritten(), std::optional<std::int64_t>(50));
}

TEST_P(ioBackgroundWriter, TheFirstFailureStopsTheWriterAndReachesTheCaller) {
  std::vector<std::int64_t> written;
  BackgroundWriter writer(
      [&](const FrameData& d) {
        if (d.frame == 3) throw std::runtime_error("frame_0003.csv: error: cannot write");
        written.push_back(d.frame);
      },
      GetParam());
  std::int64_t refusedAt = 0;
  try {
    for (std::int64_t f = 1; f <= 10; ++f) {
      refusedAt = f;
      writer.submit(frameNumbered(f));
    }
    writer.finish();
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "frame_0003.csv: error: cannot write");
  }
  // Inline, frame 3's own submit throws; overlapped, the next one (or the one after, when the
  // writer had not started frame 3 yet) does. Nothing after frame 3 is written either way.
  EXPECT_GE(refusedAt, 3);
  EXPECT_LE(refusedAt, 5);
  EXPECT_EQ(written, (std::vector<std::int64_t>{1, 2}));
  EXPECT_EQ(writer.lastWritten(), std::optional<std::int64_t>(2));
  writer.drain();  // idle, throws nothing
  EXPECT_THROW(writer.finish(), std::runtime_error);
}

INSTANTIATE_TEST_SUITE_P(OverlappedAndInline, ioBackgroundWriter, ::testing::Bool(),
                         [](const auto& p) { return p.param ? "Overlapped" : "Inline"; });

// The caller makes frame 2 while frame 1 is written; handing frame 2 over waits until frame 1 is
// done. So two frames exist at once, the one being written and the one being made, never more.
TEST(ioBackgroundWriterBound, HandingOverWaitsForTheFrameBeingWritten) {
  Gate gate;
  std::atomic<int> writes = 0;
  BackgroundWriter writer(
      [&](const FrameData&) {
        gate.wait();
        ++writes;
      },
      true);
  writer.submit(frameNumbered(1));  // returns at once: the writer was idle
  gate.waitForWriter(1);            // the writer holds frame 1
  std::atomic<bool> secondHandedOver = false;
  std::thread caller([&] {
    writer.submit(frameNumbered(2));
    secondHandedOver = true;
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  EXPECT_FALSE(secondHandedOver) << "frame 2 was taken while frame 1 was being written";
  gate.letOneGo();  // frame 1 done: frame 2 goes in
  caller.join();
  EXPECT_TRUE(secondHandedOver);
  EXPECT_EQ(writer.lastWritten(), std::optional<std::int64_t>(1));
  gate.letOneGo();
  writer.finish();
  EXPECT_EQ(writes, 2);
  EXPECT_EQ(writer.lastWritten(), std::optional<std::int64_t>(2));
}

}  // namespace
}  // namespace tickfx::io
