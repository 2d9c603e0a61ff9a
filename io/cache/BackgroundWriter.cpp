#include "io/cache/BackgroundWriter.h"

#include <chrono>
#include <utility>

namespace tickfx::io {

BackgroundWriter::BackgroundWriter(std::function<void(const FrameData&)> write, bool overlapped)
    : write_(std::move(write)), overlapped_(overlapped) {
  if (overlapped_) thread_ = std::thread([this] { run(); });
}

BackgroundWriter::~BackgroundWriter() {
  if (!thread_.joinable()) return;
  {
    const std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  changed_.notify_all();
  thread_.join();
}

void BackgroundWriter::rethrowLocked() {
  if (error_) std::rethrow_exception(error_);
}

void BackgroundWriter::submit(FrameData frame) {
  if (!overlapped_) {
    {
      const std::lock_guard lock(mutex_);
      rethrowLocked();
    }
    writeOne(frame);
    const std::lock_guard lock(mutex_);
    rethrowLocked();
    return;
  }
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [&] { return (error_ || !pending_) && !busy_; });
  rethrowLocked();
  pending_ = std::move(frame);
  lock.unlock();
  changed_.notify_all();
}

void BackgroundWriter::finish() {
  drain();
  const std::lock_guard lock(mutex_);
  rethrowLocked();
}

void BackgroundWriter::drain() {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [&] { return (error_ || !pending_) && !busy_; });
}

std::optional<std::int64_t> BackgroundWriter::lastWritten() const {
  const std::lock_guard lock(mutex_);
  return lastWritten_;
}

double BackgroundWriter::writeSeconds() const {
  const std::lock_guard lock(mutex_);
  return writeSeconds_;
}

void BackgroundWriter::writeOne(const FrameData& frame) {
  const auto start = std::chrono::steady_clock::now();
  std::exception_ptr error;
  try {
    write_(frame);
  } catch (...) {
    error = std::current_exception();
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const std::lock_guard lock(mutex_);
  writeSeconds_ += seconds;
  if (error) {
    error_ = error;
  } else {
    lastWritten_ = frame.frame;
  }
}

void BackgroundWriter::run() {
  std::unique_lock lock(mutex_);
  for (;;) {
    // A stop waits for nothing but the frame in hand: a pending frame is written first, unless
    // a write has failed (then nothing more is).
    changed_.wait(lock, [&] { return stopping_ || pending_.has_value(); });
    if (!pending_ || error_) return;
    FrameData frame = std::move(*pending_);
    pending_.reset();
    busy_ = true;
    lock.unlock();
    writeOne(frame);
    lock.lock();
    busy_ = false;
    changed_.notify_all();
  }
}

}  // namespace tickfx::io
