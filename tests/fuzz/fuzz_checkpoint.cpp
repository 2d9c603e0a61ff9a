// libFuzzer target: io::readCheckpoint, the reader behind `tickfx run --resume`.
//
// A checkpoint ends with a checksum of every byte before it and names the effect it was written
// for: an input that got those right by chance would be one in 2⁶⁴, so the target stamps both
// into each input first (the effect hash at its header offset, the checksum as the last 8 bytes)
// and the fuzzer explores what lies between. Any input must then either be refused with the
// reader's std::runtime_error, leaving the system as it was, or be read into a system that runs.
//
// The seeds in tests/fuzz/corpus/checkpoint were written by this target itself:
//   TICKFX_FUZZ_WRITE_SEED=tests/fuzz/corpus/checkpoint/rope_and_spray.tfxc
//   build/.../fuzz_checkpoint -runs=0
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <stdexcept>
#include <string>

#include "../support/LittleEndianBytes.h"
#include "FuzzScratch.h"
#include "io/effect/EffectLoader.h"
#include "io/state/Checkpoint.h"
#include "io/util/Fingerprint.h"
#include "particles/StateHash.h"

namespace {

// Springs (a rope pinned at one end), emission with lifetimes, and velocity Verlet (the scheme
// that keeps an acceleration column): every part of the format has rows to read.
constexpr const char* kEffect = R"(format_version = 1
[simulation]
step_rate = 60
integrator = "velocity_verlet"
seed = 11
max_particles = 64
[[emitters]]
type = "rope"
name = "rope"
start = [0.0, 1.0, 0.0]
end = [1.0, 1.0, 0.5]
count = 6
pin_start = true
mass = 0.05
stiffness = 50.0
damping = 0.05
[[emitters]]
name = "spray"
shape = "point"
rate = 120.0
speed = 2.0
lifetime = 0.25
[[forces]]
type = "gravity"
[[forces]]
type = "drag"
k = 0.5
[output]
fps = 30
seconds = 1.0
)";

constexpr std::uint64_t kEffectHash = 0x6b63656866757a7aULL;
constexpr std::size_t kEffectHashOffset = 8 + 4 + 4 + 8;  // after magic, version, flags, length
constexpr std::size_t kChecksumBytes = 8;

std::unique_ptr<tickfx::ParticleSystem> makeSystem() {
  static const auto effect = [] {
    const std::string text = kEffect;
    return tickfx::fuzz::writeScratch(
        "effect.toml", reinterpret_cast<const std::uint8_t*>(text.data()), text.size());
  }();
  tickfx::LoadOptions options;
  options.threads = 1;
  options.offline = true;
  auto loaded = tickfx::loadEffect(effect, {}, options);
  if (!loaded.ok()) {
    std::fputs(loaded.text().c_str(), stderr);
    std::abort();
  }
  return std::move(loaded.system);
}

// A hash of what readCheckpoint() replaces: the pool, the clock and the driver's counters.
std::uint64_t everythingRestored(const tickfx::ParticleSystem& system) {
  const auto& d = system.driver();
  std::uint64_t h = tickfx::stateHash(system.pool());
  for (const std::int64_t v :
       {system.tickCount(), d.ticksIssued(), d.ticksDroppedTotal(), d.ticksDue(), d.remainder()}) {
    h = (h ^ static_cast<std::uint64_t>(v)) * 0x100000001b3ULL;
  }
  return h;
}

using tickfx::test::storeU64;

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  if (const char* seed = std::getenv("TICKFX_FUZZ_WRITE_SEED")) {
    auto system = makeSystem();
    system->stepTicks(40);  // the rope swinging, spray particles alive and some already dead
    tickfx::io::CheckpointInfo info;
    info.effectHash = kEffectHash;
    info.frame = 20;
    info.elapsed = 20 * (tickfx::kFlicksPerSecond / 30);
    tickfx::io::writeCheckpoint(seed, *system, info);
  }
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string bytes(reinterpret_cast<const char*>(data), size);
  if (bytes.size() >= kEffectHashOffset + 8 + kChecksumBytes) {
    storeU64(bytes, kEffectHashOffset, kEffectHash);
    const std::size_t covered = bytes.size() - kChecksumBytes;
    storeU64(bytes, covered,
             tickfx::io::piecewiseFingerprint(std::string_view(bytes).substr(0, covered)));
  }
  const auto path = tickfx::fuzz::writeScratch(
      "state.ckpt", reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
  // Loading the effect costs more than most reads: a system is reused for as long as every read
  // is refused, which (checked below) leaves it as it was, and made anew after one is accepted.
  static std::unique_ptr<tickfx::ParticleSystem> system;
  static std::uint64_t before = 0;
  if (!system) {
    system = makeSystem();
    before = everythingRestored(*system);
  }
  try {
    tickfx::io::readCheckpoint(path, *system, kEffectHash);
  } catch (const std::runtime_error&) {
    if (everythingRestored(*system) != before) __builtin_trap();  // a refusal changed it
    return 0;
  }
  system->stepTicks(3);  // what was accepted must run
  system.reset();
  return 0;
}
