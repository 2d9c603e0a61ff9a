// Hash logs: one run's state hash after every tick and frame, with the machine that made them, so
// two machines of a farm can be compared without sharing anything but a text file.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "particles/Clock.h"

namespace tickfx::io {

/// Who made the log and of what. The first group is information for a reader; the effect's
/// identity (fingerprint, seed, step rate) and the run's frames decide whether two runs are
/// comparable at all.
struct HashLogHeader {
  std::string machine;            // uname: system, release, architecture
  std::string cpu;                // /proc/cpuinfo's model name
  std::string compiler;           // the compiler that built tickfx, with its version
  std::string build;              // CMake build type
  std::string version;            // tickfx version
  std::string effect;             // the effect file as it was named (information only)
  std::uint64_t fingerprint = 0;  // the effect file's bytes and every --set (io::effectFingerprint)
  std::uint64_t seed = 0;
  std::int64_t stepRateHz = 0;
  Flicks length = 0;  // the run's length
  FrameRate fps;      // frames of 1/fps s cut that length (the last one shortened)
  std::int64_t frames = 0;
  std::int64_t ticks = 0;
  std::vector<std::string> columns;  // stateColumnNames(), in order
};

/// The state after tick `tick`: stateHash() and stateColumnHashes().
struct HashLogTick {
  std::int64_t tick = 0;
  std::uint64_t state = 0;
  std::vector<std::uint64_t> columns;
};

/// What frame `frame` shows (frameHash() of its captured FrameData), reached after tick `tick`.
struct HashLogFrame {
  std::int64_t frame = 0;
  std::int64_t tick = 0;
  std::uint64_t hash = 0;
};

/// The whole state after tick `tick`: stateRowBits() of every row, in id order.
struct HashLogSnapshot {
  std::int64_t tick = 0;
  std::vector<std::vector<std::uint64_t>> rows;
};

struct HashLog {
  HashLogHeader header;
  std::vector<HashLogTick> ticks;          // ticks 1 .. header.ticks, in order
  std::vector<HashLogFrame> frames;        // frames 1 .. header.frames, in order
  std::vector<HashLogSnapshot> snapshots;  // ascending ticks
};

/// Writes `log` as text (see the README, "Check your own effects"), atomically. Throws
/// std::runtime_error naming the path when it cannot.
void writeHashLog(const std::filesystem::path& path, const HashLog& log);

/// Reads and checks a whole log: every header key, every tick and frame in order and complete,
/// hex fields of the right width, and the closing "end" line. Throws std::runtime_error
/// "PATH:LINE: error: what is wrong (what is expected)" at the first fault; a log cut short is
/// reported at the line after its last one.
HashLog readHashLog(const std::filesystem::path& path);

}  // namespace tickfx::io
