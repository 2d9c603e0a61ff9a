#include "app/DeterminismCheck.h"

#include <algorithm>
#include <chrono>
#include <stdexcept>

#include "app/FrameTimes.h"
#include "io/effect/EffectBuilder.h"
#include "particles/ParticleSystem.h"
#include "particles/StateHash.h"

namespace tickfx::app {
namespace {

// Irregular frames as a recording of a stuttering viewport would give them: long and short
// frames, none a multiple of the step, cycling until the run's length is reached.
std::vector<Flicks> irregularFrames(Flicks total) {
  const double pattern[] = {0.021, 0.0137, 0.052, 0.0071, 0.099, 0.033, 0.0042, 0.0618};
  std::vector<Flicks> frames;
  Flicks sum = 0;
  for (std::size_t i = 0; sum < total; ++i) {
    frames.push_back(std::min(flicksFromSeconds(pattern[i % std::size(pattern)]), total - sum));
    sum += frames.back();
  }
  return frames;
}

}  // namespace

std::vector<DriveCase> standardDriveCases(Flicks total, const std::vector<int>& threadCounts,
                                          const std::optional<std::vector<Flicks>>& recorded) {
  std::vector<DriveCase> cases;
  const std::pair<const char*, FrameRate> rates[] = {
      {"24 fps", {24, 1}}, {"25 fps", {25, 1}},
      {"30 fps", {30, 1}}, {"30000/1001 fps", {30000, 1001}},
      {"60 fps", {60, 1}}, {"144 fps", {144, 1}}};
  for (const auto& [label, rate] : rates) cases.push_back({label, fixedRateFrames(rate, total), 1});
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    cases.push_back({"jitter " + std::to_string(seed), jitteredFrames(seed, total), 1});
  }
  cases.push_back({recorded ? "frame-times file" : "recorded frames",
                   recorded ? *recorded : irregularFrames(total), 1});
  for (int threads : threadCounts) {
    if (threads == 1) continue;
    cases.push_back({"60 fps", fixedRateFrames({60, 1}, total), threads});
    cases.push_back({"jitter 1", jitteredFrames(1, total), threads});
  }
  return cases;
}

DriveTrace traceDrive(const io::EffectSettings& effect, const DriveCase& drive,
                      const std::vector<std::int64_t>& onlyTicks) {
  const auto system = io::buildOfflineSystem(effect, drive.threads);
  DriveTrace trace;
  trace.label = drive.label;
  trace.threads = drive.threads;
  system->setTickObserver([&](const ParticleSystem& s) {
    if (!onlyTicks.empty() &&
        !std::binary_search(onlyTicks.begin(), onlyTicks.end(), s.tickCount()))
      return;
    trace.ticks.push_back(s.tickCount());
    trace.hashes.push_back(stateHash(s));
  });
  const auto start = std::chrono::steady_clock::now();
  for (Flicks frame : drive.frames) trace.ticksDropped += system->advance(frame).ticksDropped;
  trace.wallSeconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return trace;
}

io::FrameData stateAfterTick(const io::EffectSettings& effect, const DriveCase& drive,
                             std::int64_t tick) {
  const auto system = io::buildOfflineSystem(effect, drive.threads);
  io::FrameData state;
  bool reached = false;
  system->setTickObserver([&](const ParticleSystem& s) {
    if (s.tickCount() != tick) return;
    const ParticlePool& pool = s.pool();
    const auto n = static_cast<Eigen::Index>(pool.size());
    state.resize(pool.size(), {});
    state.timeSeconds = s.timeSeconds();
    state.id.assign(pool.id().begin(), pool.id().begin() + n);
    for (int c = 0; c < 3; ++c) {
      state.position[c] = pool.position()[c].head(n);
      state.velocity[c] = pool.velocity()[c].head(n);
    }
    state.age.resize(n);
    pool.ages(0, pool.size(), state.age.data());
    state.life = pool.lifetime().head(n);
    state.mass = pool.mass().head(n);
    reached = true;
  });
  for (std::size_t f = 0; f < drive.frames.size() && !reached; ++f)
    system->advance(drive.frames[f]);
  return state;
}

Divergence firstDivergence(const std::vector<DriveTrace>& traces) {
  Divergence d;
  if (traces.empty()) return d;
  const DriveTrace& reference = traces.front();
  for (std::size_t i = 0; i < reference.ticks.size(); ++i) {
    std::vector<std::size_t> differing;
    for (std::size_t r = 1; r < traces.size(); ++r) {
      const bool same = i < traces[r].ticks.size() && traces[r].ticks[i] == reference.ticks[i] &&
                        traces[r].hashes[i] == reference.hashes[i];
      if (!same) differing.push_back(r);
    }
    if (!differing.empty()) return {reference.ticks[i], differing};
  }
  // The reference may have stopped early while another went on.
  for (std::size_t r = 1; r < traces.size(); ++r) {
    if (traces[r].ticks.size() != reference.ticks.size()) d.runs.push_back(r);
  }
  if (!d.runs.empty()) {
    d.tick = reference.ticks.empty() ? 0 : reference.ticks.back() + 1;
  }
  return d;
}

}  // namespace tickfx::app
