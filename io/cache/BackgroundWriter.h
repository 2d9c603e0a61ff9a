// Frames written on a thread of their own while the simulation goes on.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <exception>
#include <functional>
#include <mutex>
#include <optional>
#include <thread>

#include "io/cache/FrameData.h"

namespace tickfx::io {

/// Writes frames in the order they are handed over, one at a time, on its own thread (or on the
/// caller's, when not `overlapped`: the same files, later). At most two frames exist at once: the
/// one being written and the one the caller is making; submit() waits for the writer to be free.
/// The first write that throws stops the writer: submit() and finish() rethrow that exception,
/// and no later frame is written.
class BackgroundWriter {
 public:
  /// `write` writes every file of one frame (see writeFrameCaches); it runs on the writer's
  /// thread, one frame at a time.
  BackgroundWriter(std::function<void(const FrameData&)> write, bool overlapped);
  /// Waits for the frame in hand (its files end whole or not at all); drops any error.
  ~BackgroundWriter();
  BackgroundWriter(const BackgroundWriter&) = delete;
  BackgroundWriter& operator=(const BackgroundWriter&) = delete;

  /// Hands `frame` over once the previous one is written; rethrows a failed write's exception.
  void submit(FrameData frame);
  /// Returns once every frame handed over is written; rethrows a failed write's exception.
  void finish();
  /// Returns once the writer is idle (every frame written, or a write failed), throwing nothing:
  /// for a caller that is stopping for another reason and must know which frames are whole.
  void drain();

  /// The frame number of the last frame whose files are all written (nothing before the first).
  std::optional<std::int64_t> lastWritten() const;
  /// Seconds spent writing, summed over frames.
  double writeSeconds() const;

 private:
  void run();
  void writeOne(const FrameData& frame);
  void rethrowLocked();

  std::function<void(const FrameData&)> write_;
  bool overlapped_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::optional<FrameData> pending_;  // handed over, not yet written
  bool busy_ = false;                 // the writer holds a frame
  bool stopping_ = false;
  std::exception_ptr error_;
  std::optional<std::int64_t> lastWritten_;
  double writeSeconds_ = 0.0;
  std::thread thread_;  // last: started once everything above exists
};

}  // namespace tickfx::io
