// Checkpoints: a run resumed from one reaches the uninterrupted run's state bit for bit, and a
// file that is truncated, corrupted or meant for another effect is refused without touching the
// system it was to be read into.
#include <gtest/gtest.h>
#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include <unistd.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "CoreTestSupport.h"
#include "FileSizeLimit.h"
#include "LittleEndianBytes.h"
#include "fields/Gravity.h"
#include "fields/SpringNetwork.h"
#include "integrators/Integrator.h"
#include "io/effect/EffectParser.h"
#include "io/state/Checkpoint.h"
#include "particles/StateHash.h"
#include "tests/support/FileBytes.h"

namespace fs = std::filesystem;

namespace tickfx::io {
namespace {

using test::fileBytes;
using test::JitteredFrames;

constexpr std::uint64_t kEffect = 0x0123456789abcdefULL;
constexpr std::uint64_t kFrameSeed = 99;
// Frames of 1/240 s to 1/12 s (up to 5 ticks at 60 Hz) against a cap of 3 ticks per frame: the
// driver drops (or owes) ticks and its remainder is rarely zero, so all its state is exercised.
constexpr Flicks kMinFrame = kFlicksPerSecond / 240;
constexpr Flicks kMaxFrame = kFlicksPerSecond / 12;
constexpr std::int64_t kTicksPerFrameCap = 3;

SystemSettings settingsFor(const std::string& integrator,
                           OverrunPolicy policy = OverrunPolicy::DropExcess) {
  SystemSettings s = test::referenceSettings(integrator);
  s.maxTicksPerFrame = kTicksPerFrameCap;
  s.overrunPolicy = policy;
  return s;
}

// The reference fountain (rate, burst, spread, jittered lifetimes; gravity, drag, wind) with two
// custom attributes.
std::unique_ptr<ParticleSystem> makeSystem(const SystemSettings& settings,
                                           const std::vector<std::string>& attributes = {"heat",
                                                                                         "spin"}) {
  auto system = test::referenceSystem(settings);
  for (const std::string& a : attributes) system->editPool().addAttribute(a, 0.25f);
  return system;
}

// Gives the attributes a history of their own (each value depends on every earlier frame), so
// a checkpoint that lost them could not be rebuilt from the other columns.
void evolveAttributes(ParticleSystem& system) {
  ParticlePool& pool = system.editPool();
  const std::size_t heat = pool.findAttribute("heat"), spin = pool.findAttribute("spin");
  for (std::size_t i = 0; i < pool.size(); ++i) {
    const auto r = static_cast<Eigen::Index>(i);
    if (heat != ParticlePool::npos) {
      pool.attribute(heat)[r] = pool.attribute(heat)[r] * 0.5f + pool.position().y[r];
    }
    if (spin != ParticlePool::npos) pool.attribute(spin)[r] += 1.0f;
  }
}

// One frame of the test's run: what the caller of a system does each frame.
AdvanceResult frame(ParticleSystem& system, JitteredFrames& frames, Flicks* elapsed = nullptr) {
  const Flicks duration = frames.next();
  if (elapsed != nullptr) *elapsed += duration;
  const AdvanceResult r = system.advance(duration);
  evolveAttributes(system);
  return r;
}

// Everything observable about a system's state between ticks.
struct Snapshot {
  std::uint64_t hash = 0;
  std::int64_t tick = 0;
  std::int64_t ticksIssued = 0, ticksDropped = 0, ticksDue = 0, remainder = 0;
  std::size_t size = 0, firstUnstepped = 0;
  float alpha = 0.0f;

  static Snapshot of(const ParticleSystem& s) {
    return {stateHash(s.pool()),
            s.tickCount(),
            s.driver().ticksIssued(),
            s.driver().ticksDroppedTotal(),
            s.driver().ticksDue(),
            s.driver().remainder(),
            s.pool().size(),
            s.pool().firstUnstepped(),
            s.alpha()};
  }
  bool operator==(const Snapshot&) const = default;
};

void PrintTo(const Snapshot& s, std::ostream* os) {
  *os << "{hash " << hashToHex(s.hash) << ", tick " << s.tick << ", issued " << s.ticksIssued
      << ", dropped " << s.ticksDropped << ", due " << s.ticksDue << ", remainder " << s.remainder
      << ", alpha " << s.alpha << ", size " << s.size << ", firstUnstepped " << s.firstUnstepped
      << "}";
}

void writeBytes(const fs::path& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

using test::loadU64;
using test::storeU32;
using test::storeU64;

// The checksum of format 4 written out serially: fingerprint() of each 1 MiB piece, then the
// fingerprint of the byte count and the pieces' fingerprints, each as 8 little-endian bytes.
std::uint64_t referenceChecksum(std::string_view bytes) {
  std::string words;
  const auto word = [&](std::uint64_t v) {
    for (int i = 0; i < 8; ++i) words.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
  };
  word(bytes.size());
  for (std::size_t at = 0; at < bytes.size(); at += std::size_t{1} << 20)
    word(fingerprint(bytes.substr(at, std::size_t{1} << 20)));
  return fingerprint(words);
}

// Makes an edited file self-consistent again (length and checksum), so that only the edit is
// wrong with it.
void reseal(std::string& bytes) {
  storeU64(bytes, 16, bytes.size());
  storeU64(bytes, bytes.size() - 8,
           referenceChecksum(std::string_view(bytes).substr(0, bytes.size() - 8)));
}

// Offset of the particle count: header, step rate, integrator name, then 68 bytes of scalars.
std::size_t particleCountOffset(const std::string& integrator) {
  return 32 + 8 + 4 + integrator.size() + 76;
}

class ioCheckpoint : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = std::string(info->test_suite_name()) + "_" + info->name();
    for (char& c : name) c = std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
    dir_ = fs::temp_directory_path() / ("tickfx_ckpt_" + std::to_string(::getpid()) + "_" + name);
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::set<std::string> entries() const {
    std::set<std::string> names;
    for (const auto& e : fs::directory_iterator(dir_)) names.insert(e.path().filename().string());
    return names;
  }

  fs::path dir_;
};

// ---- resuming -------------------------------------------------------------------------------

class ioCheckpointResume
    : public ioCheckpoint,
      public ::testing::WithParamInterface<std::tuple<std::string, OverrunPolicy>> {};

TEST_P(ioCheckpointResume, ResumedRunMatchesTheUninterruptedOneBitForBit) {
  const auto& [integrator, policy] = GetParam();
  const SystemSettings settings = settingsFor(integrator, policy);
  constexpr int kFrames = 150, kCheckpointFrame = 61;

  // The uninterrupted run, remembering what each frame after the checkpoint decided.
  std::vector<AdvanceResult> expected;
  Snapshot expectedEnd;
  {
    auto a = makeSystem(settings);
    JitteredFrames frames(kFrameSeed, kMinFrame, kMaxFrame);
    for (int f = 0; f < kFrames; ++f) {
      const AdvanceResult r = frame(*a, frames);
      if (f >= kCheckpointFrame) expected.push_back(r);
    }
    expectedEnd = Snapshot::of(*a);
  }

  // The interrupted run: stop after kCheckpointFrame frames and throw the system away.
  const fs::path path = dir_ / "run.ckpt";
  Snapshot atCheckpoint;
  Flicks elapsed = 0;
  {
    auto b = makeSystem(settings);
    JitteredFrames frames(kFrameSeed, kMinFrame, kMaxFrame);
    for (int f = 0; f < kCheckpointFrame; ++f) frame(*b, frames, &elapsed);
    atCheckpoint = Snapshot::of(*b);
    // The test means something only if every part of the state is in play.
    ASSERT_GT(b->pool().size(), 100u);
    ASSERT_GT(b->pool().nextId(), b->pool().size()) << "some particles should have died";
    ASSERT_NE(b->driver().remainder(), 0);
    if (policy == OverrunPolicy::DropExcess) {
      ASSERT_GT(b->driver().ticksDroppedTotal(), 0);
    } else {
      ASSERT_GT(b->driver().ticksPending(), 0) << "ticks should be owed";
    }
    if (integrator == "velocity_verlet") {
      ASSERT_NE(b->pool().acceleration().y[0], 0.0f) << "velocity Verlet keeps a(t) between ticks";
    }
    writeCheckpoint(path, *b, CheckpointInfo{kEffect, kCheckpointFrame, elapsed});
  }

  auto c = makeSystem(settings);
  const CheckpointInfo info = readCheckpoint(path, *c, kEffect);
  EXPECT_EQ(info.effectHash, kEffect);
  EXPECT_EQ(info.frame, kCheckpointFrame);
  EXPECT_EQ(info.elapsed, elapsed);
  EXPECT_EQ(Snapshot::of(*c), atCheckpoint);
  EXPECT_EQ(c->pool().firstUnstepped(), c->pool().size());

  JitteredFrames frames(kFrameSeed, kMinFrame, kMaxFrame);
  for (int f = 0; f < kCheckpointFrame; ++f) frames.next();
  for (int f = kCheckpointFrame; f < kFrames; ++f) {
    const AdvanceResult r = frame(*c, frames);
    const AdvanceResult& e = expected[static_cast<std::size_t>(f - kCheckpointFrame)];
    ASSERT_EQ(r.ticks, e.ticks) << "frame " << f;
    ASSERT_EQ(r.ticksDropped, e.ticksDropped) << "frame " << f;
    ASSERT_EQ(r.ticksPending, e.ticksPending) << "frame " << f;
    ASSERT_EQ(test::bitsOf(r.alpha), test::bitsOf(e.alpha)) << "frame " << f;
  }
  EXPECT_NE(expectedEnd.hash, atCheckpoint.hash);
  EXPECT_EQ(Snapshot::of(*c), expectedEnd);
}

INSTANTIATE_TEST_SUITE_P(
    EveryIntegrator, ioCheckpointResume,
    ::testing::Combine(::testing::ValuesIn(integratorNames()),
                       ::testing::Values(OverrunPolicy::DropExcess, OverrunPolicy::FallBehind)),
    [](const auto& p) {
      return std::get<0>(p.param) +
             (std::get<1>(p.param) == OverrunPolicy::DropExcess ? "_drop" : "_fall_behind");
    });

// The target need not be fresh: a system that has run further, with more particles and other
// ticks, is replaced whole.
TEST_F(ioCheckpoint, RestoresIntoASystemThatHasRunFurther) {
  const SystemSettings settings = settingsFor("velocity_verlet");
  const fs::path path = dir_ / "early.ckpt";
  Snapshot early, late;
  {
    auto a = makeSystem(settings);
    JitteredFrames frames(kFrameSeed, kMinFrame, kMaxFrame);
    for (int f = 0; f < 20; ++f) frame(*a, frames);
    early = Snapshot::of(*a);
    writeCheckpoint(path, *a, CheckpointInfo{kEffect, 20, 0});
    for (int f = 20; f < 40; ++f) frame(*a, frames);
    late = Snapshot::of(*a);
  }
  auto used = makeSystem(settings);
  JitteredFrames other(7, kMinFrame, kMaxFrame);
  for (int f = 0; f < 90; ++f) frame(*used, other);
  ASSERT_GT(used->pool().size(), early.size);

  readCheckpoint(path, *used, kEffect);
  EXPECT_EQ(Snapshot::of(*used), early);
  JitteredFrames frames(kFrameSeed, kMinFrame, kMaxFrame);
  for (int f = 0; f < 20; ++f) frames.next();
  for (int f = 20; f < 40; ++f) frame(*used, frames);
  EXPECT_EQ(Snapshot::of(*used), late);
}

// Rows past a pool's size are storage, not state, and may hold anything (a death flag left by a
// compaction, say): growing into them on restore must not bring it back.
TEST_F(ioCheckpoint, StaleRowsPastTheTargetsSizeDoNotLeakIn) {
  const SystemSettings settings = settingsFor("semi_implicit_euler");
  const fs::path path = dir_ / "run.ckpt";
  auto a = makeSystem(settings);
  a->stepTicks(60);
  writeCheckpoint(path, *a, CheckpointInfo{kEffect, 0, 0});
  a->stepTicks(60);

  auto b = makeSystem(settings);
  b->stepTicks(3);
  ParticlePool& pool = b->editPool();
  ASSERT_LT(pool.size(), 100u);
  pool.reserve(2048);
  std::fill(pool.dead().begin() + static_cast<std::ptrdiff_t>(pool.size()), pool.dead().end(),
            std::uint8_t{1});
  readCheckpoint(path, *b, kEffect);
  ASSERT_GT(pool.size(), 100u);
  EXPECT_EQ(std::count(pool.dead().begin(),
                       pool.dead().begin() + static_cast<std::ptrdiff_t>(pool.size()), 1),
            0);
  b->stepTicks(60);
  EXPECT_EQ(Snapshot::of(*b), Snapshot::of(*a));
}

// A full pool: the dropped-spawn count is part of the state (and of the hash).
TEST_F(ioCheckpoint, FullPoolKeepsItsDroppedSpawns) {
  SystemSettings settings = settingsFor("rk4");
  settings.maxParticles = 120;
  const fs::path path = dir_ / "full.ckpt";
  auto a = makeSystem(settings);
  a->stepTicks(40);
  ASSERT_EQ(a->pool().size(), 120u);
  ASSERT_GT(a->pool().droppedSpawns(), 0u);
  writeCheckpoint(path, *a, CheckpointInfo{kEffect, 0, 0});
  const Snapshot before = Snapshot::of(*a);
  const std::uint64_t dropped = a->pool().droppedSpawns();
  a->stepTicks(50);

  auto b = makeSystem(settings);
  readCheckpoint(path, *b, kEffect);
  EXPECT_EQ(Snapshot::of(*b), before);
  EXPECT_EQ(b->pool().droppedSpawns(), dropped);
  b->stepTicks(50);
  EXPECT_EQ(Snapshot::of(*b), Snapshot::of(*a));
}

// Tick 0: no particles, nothing in the driver.
TEST_F(ioCheckpoint, EmptyStateRoundTrips) {
  const SystemSettings settings = settingsFor("position_verlet");
  const fs::path path = dir_ / "empty.ckpt";
  auto a = makeSystem(settings);
  writeCheckpoint(path, *a, CheckpointInfo{kEffect, 0, 0});
  auto b = makeSystem(settings);
  b->stepTicks(30);
  readCheckpoint(path, *b, kEffect);
  EXPECT_EQ(Snapshot::of(*b), Snapshot::of(*a));
  EXPECT_EQ(b->pool().size(), 0u);
  a->stepTicks(45);
  b->stepTicks(45);
  EXPECT_EQ(Snapshot::of(*b), Snapshot::of(*a));
}

// The documented layout, byte for byte where it is cheap to say.
TEST_F(ioCheckpoint, FileLayoutIsTheDocumentedOne) {
  const SystemSettings settings = settingsFor("velocity_verlet");
  auto a = makeSystem(settings);
  JitteredFrames frames(kFrameSeed, kMinFrame, kMaxFrame);
  for (int f = 0; f < 25; ++f) frame(*a, frames);
  const fs::path path = dir_ / "layout.ckpt";
  writeCheckpoint(path, *a, CheckpointInfo{kEffect, 25, 123456789012345});
  const std::string bytes = fileBytes(path);
  const ParticlePool& pool = a->pool();
  const std::size_t n = pool.size();
  ASSERT_GT(n, 0u);

  ASSERT_NE(a->tickStartVelocities(), nullptr) << "advance() keeps them";
  const std::size_t payload = 8 + (4 + 15) + 76 + 3 * 8 + 4 + n * (14 * 4 + 8 + 4) + 4 + n * 12 +
                              (4 + 4 + 4 * n) * 2  // "heat", "spin"
                              + 8 + 8;             // no springs
  ASSERT_EQ(bytes.size(), 32 + payload + 8);
  EXPECT_EQ(bytes.substr(0, 8), "TICKFXCK");
  EXPECT_EQ(bytes.substr(8, 8), std::string("\x04\0\0\0\0\0\0\0", 8));
  EXPECT_EQ(loadU64(bytes, 16), bytes.size());
  EXPECT_EQ(loadU64(bytes, 24), kEffect);
  EXPECT_EQ(loadU64(bytes, 32), 60u);
  EXPECT_EQ(bytes.substr(40, 4 + 15), std::string("\x0f\0\0\0velocity_verlet", 19));
  const std::size_t count = particleCountOffset("velocity_verlet");
  EXPECT_EQ(loadU64(bytes, count - 56), static_cast<std::uint64_t>(a->tickCount()));
  EXPECT_EQ(loadU64(bytes, count - 48), static_cast<std::uint64_t>(a->driver().ticksIssued()));
  EXPECT_EQ(loadU64(bytes, count - 32), static_cast<std::uint64_t>(a->driver().ticksDue()));
  EXPECT_EQ(loadU64(bytes, count - 24), static_cast<std::uint64_t>(a->driver().remainder()));
  EXPECT_EQ(loadU64(bytes, count - 16), 25u);  // frame
  EXPECT_EQ(loadU64(bytes, count - 8), 123456789012345u);
  EXPECT_EQ(loadU64(bytes, count), n);
  EXPECT_EQ(loadU64(bytes, count + 8), pool.nextId());
  // The first column is position.x, raw little-endian float bits.
  const std::size_t columns = count + 3 * 8 + 4;
  for (std::size_t i = 0; i < n; i += 17) {
    std::uint32_t bits = 0;
    for (int b = 3; b >= 0; --b)
      bits = (bits << 8) | static_cast<unsigned char>(bytes[columns + 4 * i + b]);
    EXPECT_EQ(bits, test::bitsOf(pool.position().x[static_cast<Eigen::Index>(i)])) << "row " << i;
  }
  EXPECT_EQ(loadU64(bytes, columns + 14 * 4 * n), pool.id()[0]);
  EXPECT_EQ(loadU64(bytes, bytes.size() - 8),
            referenceChecksum(std::string_view(bytes).substr(0, bytes.size() - 8)));
}

// ---- refusals -------------------------------------------------------------------------------

class ioCheckpointRefusal : public ioCheckpoint {
 protected:
  void SetUp() override {
    ioCheckpoint::SetUp();
    good_ = dir_ / "good.ckpt";
    auto source = makeSystem(settingsFor("velocity_verlet"));
    JitteredFrames frames(kFrameSeed, kMinFrame, kMaxFrame);
    for (int f = 0; f < 40; ++f) frame(*source, frames);
    writeCheckpoint(good_, *source, CheckpointInfo{kEffect, 40, 0});
    bytes_ = fileBytes(good_);
    // The target has a state of its own, so touching it would show.
    target_ = makeSystem(settingsFor("velocity_verlet"));
    JitteredFrames other(5, kMinFrame, kMaxFrame);
    for (int f = 0; f < 15; ++f) frame(*target_, other);
  }

  // Reads `path` into `system`, expects exactly "PATH: error: `what`", and that `system` is as
  // it was.
  static void expectRefused(const fs::path& path, ParticleSystem& system, const std::string& what,
                            std::uint64_t effect = kEffect) {
    const Snapshot before = Snapshot::of(system);
    try {
      readCheckpoint(path, system, effect);
      ADD_FAILURE() << "accepted; expected: " << what;
    } catch (const std::runtime_error& e) {
      EXPECT_EQ(std::string(e.what()), path.string() + ": error: " + what);
    }
    EXPECT_EQ(Snapshot::of(system), before) << "the refused read changed the system";
  }

  void expectRefused(const std::string& bytes, const std::string& what) {
    const fs::path path = dir_ / "bad.ckpt";
    writeBytes(path, bytes);
    expectRefused(path, *target_, what);
  }

  fs::path good_;
  std::string bytes_;
  std::unique_ptr<ParticleSystem> target_;
};

TEST_F(ioCheckpointRefusal, TheGoodFileIsAccepted) {
  // The baseline of every refusal below: unedited, the same file reads.
  auto fresh = makeSystem(settingsFor("velocity_verlet"));
  EXPECT_EQ(readCheckpoint(good_, *fresh, kEffect).frame, 40);
}

TEST_F(ioCheckpointRefusal, MissingFileAndDirectory) {
  expectRefused(dir_ / "missing.ckpt", *target_, "cannot open checkpoint (no such file)");
  fs::create_directory(dir_ / "folder.ckpt");
  expectRefused(dir_ / "folder.ckpt", *target_, "cannot read checkpoint (it is a directory)");
}

TEST_F(ioCheckpointRefusal, TruncatedAtAnyLength) {
  const std::size_t length = bytes_.size();
  ASSERT_GT(length, 10'000u);
  const std::string whole = std::to_string(length);
  for (std::size_t cut : {0, 1, 7, 8, 11, 12, 20, 23}) {
    SCOPED_TRACE(cut);
    expectRefused(
        bytes_.substr(0, cut),
        "checkpoint is truncated (expected at least 40 bytes, found " + std::to_string(cut) + ")");
  }
  for (std::size_t cut :
       {24ul, 31ul, 32ul, 100ul, length / 2, length - 9, length - 8, length - 1}) {
    SCOPED_TRACE(cut);
    expectRefused(bytes_.substr(0, cut), "checkpoint is truncated (expected " + whole +
                                             " bytes, found " + std::to_string(cut) + ")");
  }
}

TEST_F(ioCheckpointRefusal, LongerThanTheHeaderSays) {
  expectRefused(bytes_ + "abc", "checkpoint is longer than its header says (expected " +
                                    std::to_string(bytes_.size()) + " bytes, found " +
                                    std::to_string(bytes_.size() + 3) + ")");
}

// Every single-bit flip past the length field is caught by the checksum: the effect hash, all
// of the scalars and names, a sample of every column, and the checksum itself.
TEST_F(ioCheckpointRefusal, AnyFlippedBitIsACorruptFile) {
  const std::size_t length = bytes_.size();
  std::vector<std::size_t> offsets;
  for (std::size_t i = 24; i < 400; ++i) offsets.push_back(i);
  for (std::size_t i = 400; i < length - 16; i += 53) offsets.push_back(i);
  for (std::size_t i = length - 16; i < length; ++i) offsets.push_back(i);
  for (std::size_t at : offsets) {
    SCOPED_TRACE(at);
    std::string bad = bytes_;
    bad[at] = static_cast<char>(bad[at] ^ (1 << (at % 8)));
    expectRefused(bad, "checksum mismatch (the file is corrupted)");
  }
}

// A flip in the first 24 bytes is named for the field it hit.
TEST_F(ioCheckpointRefusal, AFlippedHeaderBitNamesTheField) {
  const std::uint64_t length = bytes_.size();
  for (std::size_t at = 0; at < 24; ++at) {
    SCOPED_TRACE(at);
    std::string bad = bytes_;
    const int bit = static_cast<int>(at % 8);
    bad[at] = static_cast<char>(bad[at] ^ (1 << bit));
    if (at < 8) {
      expectRefused(bad, "not a tickfx checkpoint (it does not start with TICKFXCK)");
    } else if (at < 12) {
      const std::uint32_t version = kCheckpointVersion ^ (1u << (8 * (at - 8) + bit));
      expectRefused(bad, "checkpoint format version " + std::to_string(version) +
                             " (this build reads " + std::to_string(kCheckpointVersion) + ")");
    } else if (at == 12 && bit <= 1) {
      // Flags 1 (pending events) and 2 (a shard) are known: the checksum then finds the change.
      expectRefused(bad, "checksum mismatch (the file is corrupted)");
    } else if (at < 16) {
      expectRefused(bad, "checkpoint has unknown flags " +
                             std::to_string(1ull << (8 * (at - 12) + bit)) +
                             " (this build reads files with flags 0 to 3)");
    } else {
      const std::uint64_t said = length ^ (1ull << (8 * (at - 16) + bit));
      if (said < 40) {
        expectRefused(bad, "checkpoint header is damaged (file length " + std::to_string(said) +
                               ", expected at least 40)");
      } else if (said > length) {
        expectRefused(bad, "checkpoint is truncated (expected " + std::to_string(said) +
                               " bytes, found " + std::to_string(length) + ")");
      } else {
        expectRefused(bad, "checkpoint is longer than its header says (expected " +
                               std::to_string(said) + " bytes, found " + std::to_string(length) +
                               ")");
      }
    }
  }
}

TEST_F(ioCheckpointRefusal, NotACheckpoint) {
  std::string bad = bytes_;
  bad.replace(0, 8, "NOTACKPT");
  expectRefused(bad, "not a tickfx checkpoint (it does not start with TICKFXCK)");
  expectRefused(std::string("hi\n"), "not a tickfx checkpoint (it does not start with TICKFXCK)");
  expectRefused(std::string("ply\nformat ascii 1.0\n"),
                "not a tickfx checkpoint (it does not start with TICKFXCK)");
}

TEST_F(ioCheckpointRefusal, OtherFormatVersions) {
  // Version 1 lacks the driver's ticks due and the tick-start velocities; version 2 has age and
  // inverse-mass columns and 64-bit birth ticks; version 3 a serial checksum.
  for (std::uint32_t version : {0u, 1u, 2u, 3u, 5u, 9u, 0xffffffffu}) {
    SCOPED_TRACE(version);
    std::string bad = bytes_;
    storeU32(bad, 8, version);
    reseal(bad);  // otherwise well-formed: the version alone is refused
    expectRefused(bad,
                  "checkpoint format version " + std::to_string(version) + " (this build reads 4)");
  }
}

TEST_F(ioCheckpointRefusal, AnotherEffect) {
  expectRefused(good_, *target_,
                "checkpoint was written for another effect (effect hash 0123456789abcdef, "
                "expected 0123456789abcdee)",
                kEffect - 1);
  expectRefused(good_, *target_,
                "checkpoint was written for another effect (effect hash 0123456789abcdef, "
                "expected 0000000000000000)",
                0);
}

TEST_F(ioCheckpointRefusal, SettingsThatDisagree) {
  const std::string prefix = "checkpoint was written with simulation.";
  {
    SystemSettings s = settingsFor("velocity_verlet");
    s.stepRateHz = 120;
    auto other = makeSystem(s);
    expectRefused(good_, *other, prefix + "step_rate 60 (expected 120)");
  }
  {
    auto other = makeSystem(settingsFor("rk4"));
    expectRefused(good_, *other, prefix + "integrator velocity_verlet (expected rk4)");
  }
  {
    SystemSettings s = settingsFor("velocity_verlet");
    s.maxParticles = 5000;
    auto other = makeSystem(s);
    expectRefused(good_, *other, prefix + "max_particles 100000 (expected 5000)");
  }
  {
    SystemSettings s = settingsFor("velocity_verlet");
    s.maxTicksPerFrame = 16;
    auto other = makeSystem(s);
    expectRefused(good_, *other, prefix + "max_ticks_per_frame 3 (expected 16)");
  }
  {
    auto other = makeSystem(settingsFor("velocity_verlet", OverrunPolicy::FallBehind));
    expectRefused(good_, *other, prefix + "overrun drop (expected fall_behind)");
  }
  {
    // Threads change nothing in the results, so they are not part of the checkpoint.
    SystemSettings s = settingsFor("velocity_verlet");
    s.threads = 2;
    auto other = makeSystem(s);
    EXPECT_NO_THROW(readCheckpoint(good_, *other, kEffect));
  }
}

TEST_F(ioCheckpointRefusal, AnotherAttributeSet) {
  const std::string prefix = "checkpoint has particle attributes [heat, spin] (expected ";
  const SystemSettings s = settingsFor("velocity_verlet");
  auto fewer = makeSystem(s, {"heat"});
  expectRefused(good_, *fewer, prefix + "[heat])");
  auto more = makeSystem(s, {"heat", "spin", "charge"});
  expectRefused(good_, *more, prefix + "[heat, spin, charge])");
  auto renamed = makeSystem(s, {"heat", "spun"});
  expectRefused(good_, *renamed, prefix + "[heat, spun])");
  auto none = makeSystem(s, {});
  expectRefused(good_, *none, prefix + "[])");
  // The order is not part of the check: attributes are matched by name.
  auto swapped = makeSystem(s, {"spin", "heat"});
  readCheckpoint(good_, *swapped, kEffect);
  auto reference = makeSystem(s);
  readCheckpoint(good_, *reference, kEffect);
  for (const char* name : {"heat", "spin"}) {
    const FloatColumn& x = swapped->pool().attribute(swapped->pool().findAttribute(name));
    const FloatColumn& y = reference->pool().attribute(reference->pool().findAttribute(name));
    const auto n = static_cast<Eigen::Index>(reference->pool().size());
    EXPECT_TRUE((x.head(n) == y.head(n)).all()) << name;
  }
}

// Files with a good checksum that still do not parse (a writer's bug, or a crafted file): the
// reader checks every bound and refuses.
TEST_F(ioCheckpointRefusal, MalformedPayloadWithAGoodChecksum) {
  const std::size_t count = particleCountOffset("velocity_verlet");
  {
    std::string bad = bytes_;
    bad.erase(bad.size() - 8 - 16 - 4, 4);  // the last value of the last attribute (16 bytes of
                                            // spring counts follow it)
    reseal(bad);
    expectRefused(bad, "checkpoint is malformed (it ends inside the broken-spring count)");
  }
  {
    std::string bad = bytes_;
    storeU64(bad, bad.size() - 8 - 16, 3);  // three springs announced, none there
    reseal(bad);
    expectRefused(bad, "checkpoint is malformed (it ends inside the springs)");
  }
  {
    std::string bad = bytes_;
    storeU64(bad, count, 0xffffffffffffffffULL / 3);
    reseal(bad);
    expectRefused(bad, "checkpoint is malformed (it ends inside the particle columns)");
  }
  {
    std::string bad = bytes_;
    bad.insert(bad.size() - 8, "\x01\x02\x03\x04\x05", 5);
    reseal(bad);
    expectRefused(bad, "checkpoint is malformed (5 bytes follow the last spring)");
  }
  {
    std::string bad = bytes_;
    storeU32(bad, 40, 0xfffffff0u);  // the integrator name's length
    reseal(bad);
    expectRefused(bad, "checkpoint is malformed (it ends inside the integrator name)");
  }
  {
    std::string bad = bytes_;
    storeU64(bad, count - 56, 0x8000000000000000ULL);  // the tick count
    reseal(bad);
    expectRefused(bad, "checkpoint is malformed (negative tick count)");
  }
  // Found by fuzz_checkpoint: the driver refused this state only once the pool had been replaced,
  // with an exception the reader does not promise. FixedStepDriver::canRestore() now vets it with
  // the rest, before the system is touched.
  const std::uint64_t dropped = loadU64(bytes_, count - 40), due = loadU64(bytes_, count - 32),
                      remainder = loadU64(bytes_, count - 24);
  const auto driverState = [&](const std::string& issued, std::uint64_t dueValue) {
    return "checkpoint is malformed (a driver state no run reaches: ticks issued " + issued +
           ", dropped " + std::to_string(dropped) + ", due " + std::to_string(dueValue) +
           ", remainder " + std::to_string(remainder) + " flicks)";
  };
  {
    std::string bad = bytes_;
    storeU64(bad, count - 48, due + 2);  // ticks issued past the ticks due
    reseal(bad);
    expectRefused(bad, driverState(std::to_string(due + 2), due));
  }
  {
    std::string bad = bytes_;
    storeU64(bad, count - 48, 0x8000000000000000ULL);  // negative ticks issued
    reseal(bad);
    expectRefused(bad, driverState("-9223372036854775808", due));
  }
  // Found by fuzz_checkpoint: a birth tick of -2⁶³ overflowed the ages' tick − birth (undefined
  // behaviour) on the next tick; birth ticks are 32 bits unsigned since version 3, and one past
  // the tick is still refused. Ids and births are vetted with the pool's own rules
  // (ParticlePool::restoreProblem) before anything is restored.
  const std::uint64_t rows = loadU64(bytes_, count), nextId = loadU64(bytes_, count + 8);
  const std::int64_t tick = static_cast<std::int64_t>(loadU64(bytes_, count - 56));
  const std::size_t idAt = count + 8 + 8 + 8 + 4 + 14 * 4 * rows, birthAt = idAt + 8 * rows;
  ASSERT_GE(rows, 3u);
  const std::uint64_t id1 = loadU64(bytes_, idAt + 8);
  struct Case {
    std::size_t at;
    std::uint64_t value;
    int bytes;
    std::string why;
  };
  const Case cases[] = {
      {birthAt + 4, 0xffffffffULL, 4,
       "row 1 was born at tick 4294967295 (expected 0 to " + std::to_string(tick) + ")"},
      {birthAt + 8, static_cast<std::uint64_t>(tick) + 1, 4,
       "row 2 was born at tick " + std::to_string(tick + 1) + " (expected 0 to " +
           std::to_string(tick) + ")"},
      {idAt + 16, id1, 8,
       "row 2 has id " + std::to_string(id1) +
           " (ids rise from row to row and stay below the next id, " + std::to_string(nextId) +
           ")"},
      {idAt + 8 * (rows - 1), nextId, 8,
       "row " + std::to_string(rows - 1) + " has id " + std::to_string(nextId) +
           " (ids rise from row to row and stay below the next id, " + std::to_string(nextId) +
           ")"},
  };
  for (const Case& c : cases) {
    std::string bad = bytes_;
    if (c.bytes == 4)
      storeU32(bad, c.at, static_cast<std::uint32_t>(c.value));
    else
      storeU64(bad, c.at, c.value);
    reseal(bad);
    expectRefused(bad, "checkpoint is malformed (" + c.why + ")");
  }
}

// ---- writing --------------------------------------------------------------------------------

TEST_F(ioCheckpoint, OverwritingReplacesTheFileAndLeavesNoTemporary) {
  const SystemSettings settings = settingsFor("midpoint");
  auto a = makeSystem(settings);
  const fs::path path = dir_ / "run.ckpt";
  a->stepTicks(10);
  writeCheckpoint(path, *a, CheckpointInfo{kEffect, 1, 2});
  a->stepTicks(10);
  writeCheckpoint(path, *a, CheckpointInfo{kEffect, 3, 4});
  EXPECT_EQ(entries(), std::set<std::string>{"run.ckpt"});
  auto b = makeSystem(settings);
  EXPECT_EQ(readCheckpoint(path, *b, kEffect).frame, 3);
  EXPECT_EQ(Snapshot::of(*b), Snapshot::of(*a));
}

// The disk fills up half-way through the new file (RLIMIT_FSIZE, which binds root too): the
// old checkpoint is still there, whole and readable, and the partial temporary is gone.
TEST_F(ioCheckpoint, AFailedWriteLeavesTheOldCheckpointIntact) {
  const SystemSettings settings = settingsFor("velocity_verlet");
  auto a = makeSystem(settings);
  const fs::path path = dir_ / "run.ckpt";
  a->stepTicks(30);
  writeCheckpoint(path, *a, CheckpointInfo{kEffect, 30, 0});
  const std::string old = fileBytes(path);
  const Snapshot oldState = Snapshot::of(*a);
  a->stepTicks(30);
  ASSERT_GT(a->pool().size() * 84, 8192u) << "the new file must outgrow the limit";

  std::string message;
  {
    const test::FileSizeLimit limit(4096);
    ASSERT_TRUE(limit.set());
    try {
      writeCheckpoint(path, *a, CheckpointInfo{kEffect, 60, 0});
    } catch (const std::runtime_error& e) {
      message = e.what();
    }
  }

  EXPECT_EQ(message, path.string() + ": error: cannot write (File too large)");
  EXPECT_EQ(entries(), std::set<std::string>{"run.ckpt"});
  EXPECT_EQ(fileBytes(path), old);
  auto b = makeSystem(settings);
  EXPECT_EQ(readCheckpoint(path, *b, kEffect).frame, 30);
  EXPECT_EQ(Snapshot::of(*b), oldState);
}

// The rename cannot replace a directory: it stays as it was, and no temporary is left beside it.
TEST_F(ioCheckpoint, WritingOverADirectoryFailsCleanly) {
  auto a = makeSystem(settingsFor("rk4"));
  a->stepTicks(20);
  const fs::path path = dir_ / "run.ckpt";
  fs::create_directory(path);
  writeBytes(path / "keep", "precious");
  try {
    writeCheckpoint(path, *a, CheckpointInfo{kEffect, 0, 0});
    ADD_FAILURE() << "writing over a directory succeeded";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), path.string() + ": error: cannot write (Is a directory)");
  }
  EXPECT_EQ(entries(), std::set<std::string>{"run.ckpt"});
  EXPECT_EQ(fileBytes(path / "keep"), "precious");
}

TEST_F(ioCheckpoint, WritingIntoAMissingFolderFails) {
  auto a = makeSystem(settingsFor("rk4"));
  const fs::path path = dir_ / "no" / "such" / "run.ckpt";
  try {
    writeCheckpoint(path, *a, CheckpointInfo{kEffect, 0, 0});
    ADD_FAILURE() << "wrote into a missing folder";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()),
              path.string() + ": error: cannot write (No such file or directory)");
  }
  EXPECT_TRUE(entries().empty());
}

// ---- fingerprint ----------------------------------------------------------------------------

// Effect hashes written by one version are compared by the next: the values are pinned (and
// agree with an independent implementation of the algorithm documented in Fingerprint.h).
TEST(ioFingerprint, IsStable) {
  EXPECT_EQ(hashToHex(fingerprint("")), "0556470532b24426");
  EXPECT_EQ(hashToHex(fingerprint("tickfx")), "17ef229f63032e7f");
  EXPECT_EQ(hashToHex(fingerprint("[simulation]\nstep_rate = 60\n")), "78c5581e6d6768f3");
}

// The checkpoint checksum: its definition written out serially (referenceChecksum), on every
// thread count, one shot or streamed in uneven parts, at the sizes around its pieces (1 MiB) and
// past the 64 pieces the streaming form holds at once.
TEST(ioFingerprint, PiecewiseIsItsDefinitionOnAnyThreadCountAndStreamed) {
  const tbb::global_control workers(tbb::global_control::max_allowed_parallelism, 8);
  std::string bytes((std::size_t{66} << 20) + 3, '\0');
  std::uint64_t x = 0x9e3779b97f4a7c15ULL;
  for (char& c : bytes) {
    x ^= x << 13, x ^= x >> 7, x ^= x << 17;
    c = static_cast<char>(x);
  }
  constexpr std::size_t kMiB = std::size_t{1} << 20;
  for (const std::size_t size :
       {std::size_t{0}, std::size_t{1}, kMiB - 1, kMiB, kMiB + 1, 3 * kMiB + 5, bytes.size()}) {
    SCOPED_TRACE(size);
    const std::string_view view(bytes.data(), size);
    const std::uint64_t expected = referenceChecksum(view);
    for (const int threads : {1, 2, 3, 8}) {
      tbb::task_arena arena(threads);
      EXPECT_EQ(arena.execute([&] { return piecewiseFingerprint(view); }), expected) << threads;
    }
    PiecewiseFingerprinter streamed;
    for (std::size_t at = 0, part = 1; at < size; at += part, part = part * 3 + 7)
      streamed.add(view.substr(at, part));
    EXPECT_EQ(streamed.value(), expected);
  }
  // One flipped bit in any piece changes it.
  const std::uint64_t whole = piecewiseFingerprint(bytes);
  for (const std::size_t at : {std::size_t{0}, kMiB - 1, kMiB, 65 * kMiB, bytes.size() - 1}) {
    bytes[at] = static_cast<char>(bytes[at] ^ 4);
    EXPECT_NE(piecewiseFingerprint(bytes), whole) << at;
    bytes[at] = static_cast<char>(bytes[at] ^ 4);
  }
}

// An effect's identity is the fingerprint of the very text parsed and its overrides, each after a
// zero byte; a file that cannot be read has none (0).
TEST(ioFingerprint, AnEffectsIsOfTheTextParsedAndItsOverrides) {
  const std::string text = "[simulation]\nstep_rate = 60\n";
  EXPECT_EQ(hashToHex(parseEffect(text, "a.toml").fingerprint), "78c5581e6d6768f3");
  const std::vector<std::string> overrides{"simulation.seed=3", "simulation.step_rate=120"};
  const std::uint64_t withOverrides = parseEffect(text, "a.toml", overrides).fingerprint;
  EXPECT_EQ(withOverrides, fingerprint(text + '\0' + overrides[0] + '\0' + overrides[1]));
  EXPECT_EQ(withOverrides, effectFingerprint(text, overrides));
  const std::filesystem::path file = std::filesystem::temp_directory_path() /
                                     ("tickfx_fp_" + std::to_string(::getpid()) + ".toml");
  std::ofstream(file, std::ios::binary) << text;
  EXPECT_EQ(loadEffectFile(file, overrides).fingerprint, withOverrides);
  EXPECT_EQ(effectFileFingerprint(file, overrides), withOverrides);
  std::filesystem::remove(file);
  EXPECT_EQ(loadEffectFile(file, overrides).fingerprint, 0u) << "no file, no identity";
}

TEST(ioFingerprint, EveryBitAndTheLengthCount) {
  std::string bytes;
  for (int i = 0; i < 61; ++i) bytes.push_back(static_cast<char>(i * 37 + 11));
  const std::uint64_t base = fingerprint(bytes);
  std::set<std::uint64_t> seen{base};
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    for (int bit = 0; bit < 8; ++bit) {
      std::string flipped = bytes;
      flipped[i] = static_cast<char>(flipped[i] ^ (1 << bit));
      EXPECT_TRUE(seen.insert(fingerprint(flipped)).second) << "byte " << i << " bit " << bit;
    }
  }
  // Trailing zero bytes pad the last word, so only the length tells these apart.
  EXPECT_NE(fingerprint(std::string_view("", 0)), fingerprint(std::string_view("\0", 1)));
  EXPECT_NE(fingerprint(std::string_view("ab", 2)), fingerprint(std::string_view("ab\0", 3)));
  EXPECT_NE(fingerprint(std::string(8, '\0')), fingerprint(std::string(16, '\0')));
}

// A fingerprint made a piece at a time, however the bytes are cut, is the fingerprint of them all.
TEST(ioFingerprint, PiecesGiveTheWholesFingerprint) {
  std::string bytes;
  for (int i = 0; i < 100; ++i) bytes += static_cast<char>(i * 37 + 11);
  for (std::size_t length : {0u, 1u, 7u, 8u, 9u, 64u, 100u}) {
    const std::string_view whole(bytes.data(), length);
    for (std::size_t cut : {1u, 3u, 8u, 13u}) {
      Fingerprinter f;
      for (std::size_t at = 0; at < length; at += cut) f.add(whole.substr(at, cut));
      EXPECT_EQ(f.value(), fingerprint(whole)) << length << " in pieces of " << cut;
    }
  }
  EXPECT_EQ(Fingerprinter().value(), fingerprint(""));
}

}  // namespace
}  // namespace tickfx::io

namespace tickfx::io {
namespace {

// A rope and a cloth with breakable springs: the spring network (springs left, broken count) is
// part of the state a checkpoint carries.
TEST(ioCheckpointSprings, AResumedStructureReachesTheUninterruptedHash) {
  auto make = [] {
    SystemSettings settings;
    settings.stepRateHz = 120;
    settings.integrator = "semi_implicit_euler";
    StructureSettings rope;
    rope.shape = RopeShape{Eigen::Vector3d(0, 2, 0), Eigen::Vector3d(2, 2, 0), 20, true, false};
    rope.stiffness = 400.0;
    rope.damping = 0.5;
    rope.breakRatio = 1.02;  // gravity stretches the top links past this: some break
    StructureSettings cloth;
    cloth.shape = ClothShape{};
    cloth.time = 0.1;  // born after the checkpoint below would be too late: it is born before
    cloth.stiffness = 200.0;
    ForceSet forces;
    forces.add(std::make_unique<Gravity>());
    return std::make_unique<ParticleSystem>(settings, std::vector<EmitterSettings>{},
                                            std::move(forces),
                                            std::vector<StructureSettings>{rope, cloth});
  };
  auto whole = make();
  whole->stepTicks(240);
  ASSERT_GT(whole->springs()->brokenCount(), 0u) << "the test wants broken springs in the state";

  const fs::path path =
      fs::temp_directory_path() / ("tickfx_ckpt_springs_" + std::to_string(::getpid()));
  auto first = make();
  first->stepTicks(60);
  ASSERT_GT(first->springs()->brokenCount(), 0u);
  writeCheckpoint(path, *first, CheckpointInfo{42, 0, 0});
  auto resumed = make();
  readCheckpoint(path, *resumed, 42);
  EXPECT_EQ(resumed->springs()->springs().size(), first->springs()->springs().size());
  EXPECT_EQ(resumed->springs()->brokenCount(), first->springs()->brokenCount());
  resumed->stepTicks(180);
  EXPECT_EQ(stateHash(resumed->pool()), stateHash(whole->pool()));
  EXPECT_EQ(resumed->springs()->brokenCount(), whole->springs()->brokenCount());

  // The same file into an effect without structures is refused.
  ParticleSystem plain(SystemSettings{}, {}, ForceSet{});
  EXPECT_THROW(readCheckpoint(path, plain, 42), std::runtime_error);
  fs::remove(path);
}

}  // namespace
}  // namespace tickfx::io
