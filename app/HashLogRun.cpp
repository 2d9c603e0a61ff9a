#include "app/HashLogRun.h"

#include <sys/utsname.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include "app/FrameTimes.h"
#include "io/cache/FrameData.h"
#include "io/effect/EffectBuilder.h"
#include "particles/ParticleSystem.h"
#include "particles/StateHash.h"

namespace tickfx::app {
namespace {

std::string cpuModel() {
  std::ifstream in("/proc/cpuinfo");
  for (std::string line; std::getline(in, line);) {
    // x86 names its model; aarch64 kernels often give none, so the line is optional.
    if (line.rfind("model name", 0) == 0 && line.find(':') != std::string::npos) {
      const std::size_t start = line.find_first_not_of(" \t", line.find(':') + 1);
      return start == std::string::npos ? "unknown" : line.substr(start);
    }
  }
  return "unknown";
}

std::string compilerName() {
#if defined(__clang__)
  // __clang_version__ ends in a space ("14.0.6 ").
  std::string name = "clang++ " __clang_version__;
  name.erase(name.find_last_not_of(' ') + 1);
  return name;
#elif defined(__GNUC__)
  return "g++ " __VERSION__;
#else
  return "unknown";
#endif
}

// Calls `onFrame(frame number, system)` after each frame of the log's schedule; stops early when
// it returns false.
template <typename OnFrame>
void driveAsLogged(ParticleSystem& system, const io::HashLogHeader& h, OnFrame onFrame) {
  FrameSchedule schedule = FrameSchedule::fixedRate(h.fps, h.length);
  Flicks elapsed = 0;
  while (const std::optional<Flicks> d = schedule.next()) {
    system.advance(*d);
    elapsed += *d;
    if (!onFrame(schedule.framesDone(),
                 io::captureFrame(system, schedule.framesDone(), secondsFromFlicks(elapsed))))
      return;
  }
}

// Refuses a log of another step rate, seed or effect, checked in that order (so that a --set of
// the seed or the step rate is named as such).
void checkLogIsOfEffect(const io::EffectSettings& effect, std::uint64_t fingerprint,
                        const std::string& logName, const io::HashLogHeader& h) {
  const std::string refused = logName + ": error: the log is of another ";
  if (h.stepRateHz != effect.simulation.stepRateHz) {
    throw HashLogRefused(refused + "step rate (" + std::to_string(h.stepRateHz) + " Hz, this run " +
                         std::to_string(effect.simulation.stepRateHz) + " Hz)");
  }
  if (h.seed != effect.simulation.seed) {
    throw HashLogRefused(refused + "seed (" + std::to_string(h.seed) + ", this run " +
                         std::to_string(effect.simulation.seed) + ")");
  }
  if (h.fingerprint != fingerprint) {
    throw HashLogRefused(refused + "effect (fingerprint " + hashToHex(h.fingerprint) +
                         ", this run " + hashToHex(fingerprint) + ")");
  }
}

// The first value of `pool` that differs from `snapshot` (the log's state after the same tick),
// or else the first particle one of them lacks; nothing when they agree.
std::optional<RowDifference> firstRowDifference(const ParticlePool& pool,
                                                const io::HashLogSnapshot& snapshot,
                                                const std::vector<std::string>& columns) {
  const std::size_t common = std::min(pool.size(), snapshot.rows.size());
  for (std::size_t row = 0; row < common; ++row) {
    const std::vector<std::uint64_t> bits = stateRowBits(pool, row);
    for (std::size_t k = 0; k < bits.size(); ++k) {
      if (bits[k] != snapshot.rows[row][k])
        return RowDifference{pool.id()[row], columns[k + 1], bits[k], snapshot.rows[row][k]};
    }
  }
  if (pool.size() == snapshot.rows.size()) return std::nullopt;
  // Every common row agrees: one run has particles the other has not.
  const std::size_t first = common;
  const std::uint64_t id = first < pool.size() ? pool.id()[first] : snapshot.rows[first][0];
  return RowDifference{id, "counters", pool.size(), snapshot.rows.size()};
}

}  // namespace

io::HashLogHeader describeThisBuild() {
  io::HashLogHeader h;
  utsname u{};
  h.machine =
      ::uname(&u) == 0 ? std::string(u.sysname) + " " + u.release + " " + u.machine : "unknown";
  h.cpu = cpuModel();
  h.compiler = compilerName();
  h.build = TICKFX_BUILD;
  h.version = TICKFX_VERSION;
  return h;
}

io::HashLog recordHashLog(const io::EffectSettings& effect, io::HashLogHeader header,
                          const std::vector<std::int64_t>& snapshotTicks) {
  const auto system = io::buildOfflineSystem(effect, std::nullopt);
  io::HashLog log;
  header.columns = stateColumnNames(system->pool());
  system->setTickObserver([&](const ParticleSystem& s) {
    const ParticlePool& pool = s.pool();
    log.ticks.push_back({s.tickCount(), stateHash(s), stateColumnHashes(pool)});
    if (std::binary_search(snapshotTicks.begin(), snapshotTicks.end(), s.tickCount())) {
      io::HashLogSnapshot snapshot{s.tickCount(), {}};
      for (std::size_t row = 0; row < pool.size(); ++row)
        snapshot.rows.push_back(stateRowBits(pool, row));
      log.snapshots.push_back(std::move(snapshot));
    }
  });
  driveAsLogged(*system, header, [&](std::int64_t frame, const io::FrameData& data) {
    log.frames.push_back({frame, system->tickCount(), io::frameHash(data)});
    return true;
  });
  header.frames = static_cast<std::int64_t>(log.frames.size());
  header.ticks = system->tickCount();
  log.header = std::move(header);
  return log;
}

LogComparison compareWithHashLog(const io::EffectSettings& effect, std::uint64_t fingerprint,
                                 const std::string& logName, const io::HashLog& log) {
  const io::HashLogHeader& h = log.header;
  checkLogIsOfEffect(effect, fingerprint, logName, h);
  // tickfx 0.3.0 hashes each column in blocks (particles/StateHash.h): a log of an earlier
  // version holds hashes of the same states that this build cannot reproduce.
  int major = 0, minor = 0;
  if (std::sscanf(h.version.c_str(), "%d.%d", &major, &minor) == 2 && major == 0 && minor < 3) {
    throw HashLogRefused(logName + ": error: the log is of tickfx " + h.version +
                         ", whose state hashes are defined otherwise (since 0.3.0 each column is "
                         "hashed in blocks); record it again with this build");
  }
  const auto system = io::buildOfflineSystem(effect, std::nullopt);
  const std::vector<std::string> columns = stateColumnNames(system->pool());
  if (columns != h.columns) {
    // The same effect file with other columns: a tickfx version that hashes other state.
    throw HashLogRefused(logName +
                         ": error: the log's columns are not this build's (the log is "
                         "of tickfx " +
                         h.version + ", this is " + TICKFX_VERSION + ")");
  }

  LogComparison c;
  system->setTickObserver([&](const ParticleSystem& s) {
    const std::int64_t tick = s.tickCount();
    if (c.partTick >= 0) return;
    const ParticlePool& pool = s.pool();
    const std::uint64_t hash = stateHash(s);
    if (tick > static_cast<std::int64_t>(log.ticks.size())) {
      // Cannot happen for a log this function accepts (same rate, same length), but a log that
      // ends early must not pass as identical.
      c.partTick = tick;
      c.runHash = hash;
      return;
    }
    const io::HashLogTick& logged = log.ticks[static_cast<std::size_t>(tick - 1)];
    if (hash == logged.state) return;
    c.partTick = tick;
    c.runHash = hash;
    c.logHash = logged.state;
    const std::vector<std::uint64_t> mine = stateColumnHashes(pool);
    for (std::size_t i = 0; i < columns.size(); ++i) {
      if (mine[i] != logged.columns[i]) c.columns.push_back(columns[i]);
    }
    const auto snapshot =
        std::find_if(log.snapshots.begin(), log.snapshots.end(),
                     [&](const io::HashLogSnapshot& snap) { return snap.tick == tick; });
    if (snapshot == log.snapshots.end()) return;
    c.logHasState = true;
    c.row = firstRowDifference(pool, *snapshot, columns);
  });
  driveAsLogged(*system, h, [&](std::int64_t frame, const io::FrameData& data) {
    c.frames = frame;
    const bool logged = frame <= static_cast<std::int64_t>(log.frames.size());
    if (c.partTick < 0 && c.partFrame < 0 &&
        (!logged || log.frames[static_cast<std::size_t>(frame - 1)].hash != io::frameHash(data)))
      c.partFrame = frame;
    return c.partTick < 0;
  });
  c.ticks = system->tickCount();
  c.lastHash = stateHash(*system);
  if (c.partTick < 0 && c.ticks < h.ticks) c.partTick = c.ticks + 1;  // the log goes on
  return c;
}

}  // namespace tickfx::app
