#include "io/state/Checkpoint.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <system_error>
#include <type_traits>
#include <vector>

#include "fields/SpringNetwork.h"
#include "integrators/Integrator.h"
#include "io/util/AtomicFile.h"
#include "io/util/MergeOrder.h"
#include "particles/StateHash.h"

namespace tickfx::io {
namespace {

constexpr std::string_view kCheckpointMagic = "TICKFXCK";
// Header flag: the pending events of sub-emitters follow the springs.
constexpr std::uint32_t kPendingEventsFlag = 1;
// Header flag: the state is one shard's (particles/Shard.h): u32 index, u32 count end the payload.
constexpr std::uint32_t kShardFlag = 2;
constexpr std::uint32_t kKnownFlags = kPendingEventsFlag | kShardFlag;
constexpr std::size_t kHeaderBytes = 32;  // magic, version, flags, length, effect hash
constexpr std::size_t kTrailerBytes = 8;  // checksum
constexpr std::size_t kMinimumBytes = kHeaderBytes + kTrailerBytes;
constexpr std::size_t kVersionOffset = 8;
constexpr std::size_t kFlagsOffset = 12;
constexpr std::size_t kLengthOffset = 16;
constexpr std::size_t kEffectHashOffset = 24;

// The float columns in file order; writer and reader share this list so they cannot disagree.
// f gets null for the acceleration of a pool that does not keep it: zeros in the file.
template <typename Pool, typename F>
void forEachFloatColumn(Pool& pool, F&& f) {
  for (auto* c :
       {&pool.position(), &pool.velocity(), &pool.previousPosition(), &pool.acceleration()}) {
    const bool absent = (c == &pool.acceleration() && !pool.keepsAcceleration()) ||
                        (c == &pool.previousPosition() && !pool.keepsPrevious());
    for (int k = 0; k < 3; ++k) f(absent ? nullptr : &(*c)[k]);
  }
  for (auto* c : {&pool.lifetime(), &pool.mass()}) f(c);
}
constexpr int kFloatColumns = 14;
constexpr int kFirstPreviousColumn = 6;      // after position, velocity
constexpr int kFirstAccelerationColumn = 9;  // after position, velocity, previous position

std::uint64_t loadU64(const char* p) {
  std::uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(p[i]);
  return v;
}

std::uint32_t loadU32(const char* p) {
  std::uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(p[i]);
  return v;
}

// Bulk copies of whole columns: a memcpy on little-endian hosts (all the supported ones), byte
// by byte elsewhere so the file stays the same everywhere.
template <typename T>
void appendLittleEndian(std::string& out, const T* values, std::size_t count) {
  static_assert(sizeof(T) == 4 || sizeof(T) == 8);
  if constexpr (std::endian::native == std::endian::little) {
    out.append(reinterpret_cast<const char*>(values), count * sizeof(T));
  } else {
    for (std::size_t i = 0; i < count; ++i) {
      unsigned char bytes[sizeof(T)] = {};
      std::memcpy(bytes, &values[i], sizeof(T));
      for (std::size_t b = sizeof(T); b-- > 0;) out.push_back(static_cast<char>(bytes[b]));
    }
  }
}

template <typename T>
void loadLittleEndian(const char* in, T* values, std::size_t count) {
  static_assert(sizeof(T) == 4 || sizeof(T) == 8);
  if constexpr (std::endian::native == std::endian::little) {
    if (count > 0) std::memcpy(values, in, count * sizeof(T));
  } else {
    for (std::size_t i = 0; i < count; ++i) {
      unsigned char bytes[sizeof(T)] = {};
      for (std::size_t b = 0; b < sizeof(T); ++b)
        bytes[sizeof(T) - 1 - b] = static_cast<unsigned char>(in[i * sizeof(T) + b]);
      std::memcpy(&values[i], bytes, sizeof(T));
    }
  }
}

// Writes a checkpoint's bytes to a stream as they are made, fingerprinting them on the way (the
// trailer's checksum); without a stream it only counts them (the header's file length). A file
// of 10⁸ particles is 9 GB: it is never held whole in memory.
class Writer {
 public:
  explicit Writer(std::ostream* out) : out_(out) {}

  void u32(std::uint32_t v) {
    char b[4];
    for (int i = 0; i < 4; ++i) b[i] = static_cast<char>((v >> (8 * i)) & 0xff);
    put(b, 4);
  }
  void u64(std::uint64_t v) {
    char b[8];
    for (int i = 0; i < 8; ++i) b[i] = static_cast<char>((v >> (8 * i)) & 0xff);
    put(b, 8);
  }
  void i64(std::int64_t v) { u64(static_cast<std::uint64_t>(v)); }
  void bytes(std::string_view s) { put(s.data(), s.size()); }
  void str(std::string_view s) {
    u32(static_cast<std::uint32_t>(s.size()));
    bytes(s);
  }
  template <typename T>
  void column(const T* values, std::size_t count) {
    if (out_ == nullptr) {
      size_ += count * sizeof(T);
      return;
    }
    // A block at a time, in little-endian order whatever the host's.
    constexpr std::size_t kBlock = 1 << 16;
    std::string block;
    for (std::size_t done = 0; done < count; done += kBlock) {
      block.clear();
      appendLittleEndian(block, values + done, std::min(kBlock, count - done));
      put(block.data(), block.size());
    }
  }
  std::uint64_t size() const { return size_; }
  std::uint64_t checksum() const { return checksum_.value(); }

 private:
  void put(const char* p, std::size_t n) {
    size_ += n;
    if (out_ == nullptr) return;
    checksum_.add(std::string_view(p, n));
    out_->write(p, static_cast<std::streamsize>(n));
  }

  std::ostream* out_;
  std::uint64_t size_ = 0;
  PiecewiseFingerprinter checksum_;
};

// Only ever reached for a file whose checksum matched, i.e. one a writer of this version got
// wrong or someone crafted: every read is bounds-checked all the same.
struct Malformed {
  std::string what;
};

class CheckpointReader {
 public:
  explicit CheckpointReader(std::string_view bytes) : bytes_(bytes) {}

  std::uint32_t u32(const char* what) { return loadU32(take(4, what)); }
  std::uint64_t u64(const char* what) { return loadU64(take(8, what)); }
  std::int64_t i64(const char* what) { return static_cast<std::int64_t>(u64(what)); }
  std::string_view str(const char* what) {
    const std::uint32_t n = u32(what);
    return {take(n, what), n};
  }
  /// The raw bytes of `count` values of `width` bytes each.
  const char* column(std::size_t count, std::size_t width, const char* what) {
    if (count > (bytes_.size() - pos_) / width)
      throw Malformed{std::string("it ends inside ") + what};
    return take(count * width, what);
  }
  std::size_t remaining() const { return bytes_.size() - pos_; }

 private:
  const char* take(std::size_t n, const char* what) {
    if (n > bytes_.size() - pos_) throw Malformed{std::string("it ends inside ") + what};
    const char* p = bytes_.data() + pos_;
    pos_ += n;
    return p;
  }

  std::string_view bytes_;
  std::size_t pos_ = 0;
};

// A spring on file: ids a and b, then rest length, stiffness, damping and break ratio as float
// bits.
constexpr std::size_t kSpringBytes = 8 + 8 + 4 * 4;

[[noreturn]] void fail(const std::filesystem::path& path, const std::string& what) {
  throw std::runtime_error(path.string() + ": error: " + what);
}

// A checkpoint file's bytes, mapped read-only: the pages are the kernel's to drop and read again,
// so merging shards larger than the memory left stays within it. Checkpoints are replaced by
// renaming a new file over them (writeFileAtomically), which leaves a mapped file's bytes as
// they were: the bytes checked are the bytes read.
class FileBytes {
 public:
  explicit FileBytes(const std::filesystem::path& path) {
    std::error_code ec;
    const std::filesystem::file_status status = std::filesystem::status(path, ec);
    if (!std::filesystem::exists(status)) fail(path, "cannot open checkpoint (no such file)");
    if (std::filesystem::is_directory(status))
      fail(path, "cannot read checkpoint (it is a directory)");
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) fail(path, std::string("cannot open checkpoint (") + std::strerror(errno) + ")");
    struct stat st {};
    if (::fstat(fd, &st) != 0 || st.st_size < 0) {
      ::close(fd);
      fail(path, "cannot read checkpoint (cannot tell its size)");
    }
    size_ = static_cast<std::size_t>(st.st_size);
    if (size_ > 0) {
      void* mapped = ::mmap(nullptr, size_, PROT_READ, MAP_PRIVATE, fd, 0);
      if (mapped == MAP_FAILED) {
        const int error = errno;
        ::close(fd);
        fail(path, std::string("cannot read checkpoint (") + std::strerror(error) + ")");
      }
      data_ = static_cast<const char*>(mapped);
    }
    ::close(fd);
  }
  ~FileBytes() {
    if (data_ != nullptr) ::munmap(const_cast<char*>(data_), size_);
  }
  FileBytes(const FileBytes&) = delete;
  FileBytes& operator=(const FileBytes&) = delete;

  std::string_view view() const { return {data_ != nullptr ? data_ : "", size_}; }

 private:
  const char* data_ = nullptr;
  std::size_t size_ = 0;
};

// The scalars of a state (settings, clock, driver, counters), whoever holds the columns: every
// shard of a run has the same ones.
struct StateScalars {
  std::int64_t stepRateHz = 0;
  std::string_view integrator;
  std::uint64_t maxParticles = 0;
  std::int64_t maxTicksPerFrame = 0;
  std::uint32_t overrunPolicy = 0;
  std::int64_t tick = 0;
  std::int64_t ticksIssued = 0, ticksDropped = 0, ticksDue = 0, remainder = 0;
  CheckpointInfo info;
  std::uint64_t nextId = 0, droppedSpawns = 0;
};

// Everything the file says, parsed and checked but not yet applied; the columns still point
// into the file's bytes.
struct Parsed : StateScalars {
  std::uint64_t size = 0;
  const char* floats[kFloatColumns] = {};
  const char* ids = nullptr;
  const char* births = nullptr;
  const char* tickStartVelocities = nullptr;  // x, y, z columns, or none
  std::vector<std::pair<std::string_view, const char*>> attributes;
  std::vector<Spring> springs;
  std::uint64_t springsBroken = 0;
  std::uint32_t inheritedColumns = 0;
  std::vector<ParticleEvent> events;
  std::vector<float> eventValues;
  Shard shard;  // the whole run without the shard flag
  // The file's bytes, which the column pointers above point into (a unique_ptr: they stay put
  // when a Parsed moves).
  std::unique_ptr<const FileBytes> file;
};

// A pending event on file: u64 parent id, u32 emitter, u32 kind, u32 ordinal, f32 × 9.
constexpr std::size_t kEventBytes = 8 + 3 * 4 + 9 * 4;

void readPendingEvents(CheckpointReader& r, Parsed& p) {
  const std::uint64_t count = r.u64("the pending event count");
  p.inheritedColumns = r.u32("the inherited column count");
  if (count == 0 || count > r.remaining() / kEventBytes) {
    throw Malformed{count == 0 ? "a pending events section with no events"
                               : "it ends inside the pending events"};
  }
  p.events.resize(static_cast<std::size_t>(count));
  const auto f32 = [&](const char* what) {
    const std::uint32_t bits = r.u32(what);
    float f = 0.0f;
    std::memcpy(&f, &bits, 4);
    return f;
  };
  for (ParticleEvent& e : p.events) {
    e.parentId = r.u64("a pending event");
    e.parentEmitter = r.u32("a pending event");
    const std::uint32_t kind = r.u32("a pending event");
    if (kind < 1 || kind > 3)
      throw Malformed{"a pending event of unknown kind " + std::to_string(kind)};
    e.kind = static_cast<EmitterEvent>(kind);
    e.ordinal = r.u32("a pending event");
    for (Eigen::Vector3f* v : {&e.position, &e.velocity, &e.normal}) {
      for (int c = 0; c < 3; ++c) (*v)[c] = f32("a pending event");
    }
  }
  const std::uint64_t values = count * p.inheritedColumns;
  if (p.inheritedColumns > r.remaining() / 4 / count) {
    throw Malformed{"it ends inside the pending events' inherited values"};
  }
  p.eventValues.resize(static_cast<std::size_t>(values));
  for (float& v : p.eventValues) v = f32("an inherited value");
}

Parsed parsePayload(std::string_view payload, std::uint32_t flags) {
  const bool pendingEvents = (flags & kPendingEventsFlag) != 0;
  CheckpointReader r(payload);
  Parsed p;
  p.stepRateHz = r.i64("the step rate");
  p.integrator = r.str("the integrator name");
  p.maxParticles = r.u64("max particles");
  p.maxTicksPerFrame = r.i64("max ticks per frame");
  p.overrunPolicy = r.u32("the overrun policy");
  p.tick = r.i64("the tick count");
  p.ticksIssued = r.i64("the driver state");
  p.ticksDropped = r.i64("the driver state");
  p.ticksDue = r.i64("the driver state");
  p.remainder = r.i64("the driver state");
  p.info.frame = r.i64("the frame count");
  p.info.elapsed = r.i64("the elapsed time");
  p.size = r.u64("the particle count");
  p.nextId = r.u64("the next id");
  p.droppedSpawns = r.u64("the dropped-spawn count");
  const std::uint32_t attributes = r.u32("the attribute count");
  for (const char*& column : p.floats) column = r.column(p.size, 4, "the particle columns");
  p.ids = r.column(p.size, 8, "the id column");
  p.births = r.column(p.size, 4, "the birth-tick column");
  const std::uint32_t hasVelocities = r.u32("the tick-start velocities flag");
  if (hasVelocities > 1) throw Malformed{"a tick-start velocities flag that is not 0 or 1"};
  if (hasVelocities == 1) {
    p.tickStartVelocities = r.column(p.size, 12, "the tick-start velocity columns");
  }
  for (std::uint32_t a = 0; a < attributes; ++a) {
    const std::string_view name = r.str("an attribute name");
    p.attributes.emplace_back(name, r.column(p.size, 4, "an attribute column"));
  }
  const std::uint64_t springs = r.u64("the spring count");
  p.springsBroken = r.u64("the broken-spring count");
  if (springs > r.remaining() / kSpringBytes) throw Malformed{"it ends inside the springs"};
  p.springs.resize(static_cast<std::size_t>(springs));
  for (Spring& spring : p.springs) {
    spring.a = r.u64("a spring");
    spring.b = r.u64("a spring");
    const std::uint32_t fields[4] = {r.u32("a spring"), r.u32("a spring"), r.u32("a spring"),
                                     r.u32("a spring")};
    std::memcpy(&spring.restLength, &fields[0], 4);
    std::memcpy(&spring.stiffness, &fields[1], 4);
    std::memcpy(&spring.damping, &fields[2], 4);
    std::memcpy(&spring.breakRatio, &fields[3], 4);
  }
  if (pendingEvents) readPendingEvents(r, p);
  if ((flags & kShardFlag) != 0) {
    p.shard.index = r.u32("the shard");
    p.shard.count = r.u32("the shard");
    if (const std::optional<std::string> problem = p.shard.problem())
      throw Malformed{"shard " + p.shard.text() + ": " + *problem};
  }
  if (r.remaining() != 0) {
    throw Malformed{std::to_string(r.remaining()) + " bytes follow the last " +
                    ((flags & kShardFlag) != 0 ? "section"
                     : pendingEvents           ? "pending event"
                                               : "spring")};
  }
  if (p.tick < 0) throw Malformed{"negative tick count"};
  if (p.overrunPolicy > 1)
    throw Malformed{"unknown overrun policy " + std::to_string(p.overrunPolicy)};
  return p;
}

std::string_view policyName(std::uint32_t policy) { return policy == 0 ? "drop" : "fall_behind"; }
std::uint32_t policyCode(OverrunPolicy policy) {
  return policy == OverrunPolicy::DropExcess ? 0u : 1u;
}

std::string nameList(const std::vector<std::string>& names) {
  std::string text = "[";
  for (std::size_t i = 0; i < names.size(); ++i) text += (i > 0 ? ", " : "") + names[i];
  return text + "]";
}

// The first way `system` differs from the one that wrote `p`, or nothing.
std::optional<std::string> mismatch(const Parsed& p, const ParticleSystem& system) {
  const ParticlePool& pool = system.pool();
  auto written = [](std::string_view key, const auto& found, const auto& expected) {
    auto text = [](const auto& v) {
      if constexpr (std::is_arithmetic_v<std::decay_t<decltype(v)>>)
        return std::to_string(v);
      else
        return std::string(v);
    };
    return "checkpoint was written with simulation." + std::string(key) + " " + text(found) +
           " (expected " + text(expected) + ")";
  };
  if (p.shard.index != system.shard().index || p.shard.count != system.shard().count) {
    const auto name = [](const Shard& s) {
      return s.whole() ? std::string("the whole run") : "shard " + s.text();
    };
    return "checkpoint is of " + name(p.shard) + " (expected " + name(system.shard()) + ")";
  }
  if (p.stepRateHz != system.settings().stepRateHz) {
    return written("step_rate", p.stepRateHz, system.settings().stepRateHz);
  }
  if (p.integrator != system.integrator().name()) {
    return written("integrator", p.integrator, system.integrator().name());
  }
  if (p.maxParticles != pool.maxParticles()) {
    return written("max_particles", p.maxParticles,
                   static_cast<std::uint64_t>(pool.maxParticles()));
  }
  if (p.maxTicksPerFrame != system.driver().maxTicksPerAdvance()) {
    return written("max_ticks_per_frame", p.maxTicksPerFrame, system.driver().maxTicksPerAdvance());
  }
  if (p.overrunPolicy != policyCode(system.driver().policy())) {
    return written("overrun", policyName(p.overrunPolicy),
                   policyName(policyCode(system.driver().policy())));
  }
  // Both ways round, so that a crafted file naming one attribute twice cannot leave another
  // unrestored.
  bool same = p.attributes.size() == pool.attributeCount();
  for (const auto& [name, values] : p.attributes) {
    same = same && pool.findAttribute(std::string(name)) != ParticlePool::npos;
  }
  for (std::size_t a = 0; same && a < pool.attributeCount(); ++a) {
    same = std::any_of(p.attributes.begin(), p.attributes.end(),
                       [&](const auto& stored) { return stored.first == pool.attributeName(a); });
  }
  if (!same) {
    std::vector<std::string> stored, expected;
    for (const auto& a : p.attributes) stored.emplace_back(a.first);
    for (std::size_t a = 0; a < pool.attributeCount(); ++a)
      expected.push_back(pool.attributeName(a));
    return "checkpoint has particle attributes " + nameList(stored) + " (expected " +
           nameList(expected) + ")";
  }
  if (!p.springs.empty() && system.springs() == nullptr) {
    return "checkpoint has " + std::to_string(p.springs.size()) +
           " springs (expected none: this effect has no structures)";
  }
  if (!p.events.empty()) {
    const EventEmission* events = system.events();
    if (events == nullptr) {
      return "checkpoint has " + std::to_string(p.events.size()) +
             " pending events (expected none: this effect has no sub-emitters)";
    }
    if (p.inheritedColumns != events->inheritedColumns().size()) {
      return "checkpoint has pending events with " + std::to_string(p.inheritedColumns) +
             " inherited values each (expected " +
             std::to_string(events->inheritedColumns().size()) + ")";
    }
    for (const ParticleEvent& e : p.events) {
      if (e.parentEmitter >= system.emitters().size() || e.parentId >= p.nextId) {
        return "checkpoint is malformed (a pending event of parent " + std::to_string(e.parentId) +
               " from emitter " + std::to_string(e.parentEmitter) + ")";
      }
    }
  }
  if (!system.driver().canRestore(p.ticksIssued, p.ticksDropped, p.ticksDue, p.remainder)) {
    return "checkpoint is malformed (a driver state no run reaches: ticks issued " +
           std::to_string(p.ticksIssued) + ", dropped " + std::to_string(p.ticksDropped) +
           ", due " + std::to_string(p.ticksDue) + ", remainder " + std::to_string(p.remainder) +
           " flicks)";
  }
  if (p.size > pool.maxParticles()) {
    return "checkpoint is malformed (" + std::to_string(p.size) +
           " particles, more than max_particles " + std::to_string(pool.maxParticles()) + ")";
  }
  std::vector<std::uint64_t> ids(static_cast<std::size_t>(p.size));
  std::vector<std::uint32_t> births(ids.size());
  loadLittleEndian(p.ids, ids.data(), ids.size());
  loadLittleEndian(p.births, births.data(), births.size());
  if (auto problem = ParticlePool::restoreProblem(ids, births, p.nextId, p.tick)) {
    return "checkpoint is malformed (" + *problem + ")";
  }
  return std::nullopt;
}

// Nothing in here may throw once the pool has room: the state is replaced whole or not at all.
void apply(const Parsed& p, ParticleSystem& system) {
  ParticlePool& pool = system.editPool();
  const auto n = static_cast<std::size_t>(p.size);
  // Velocity Verlet's a(t) makes the pool keep an acceleration column (all zeros need none);
  // like reserve(), an allocation that changes no value of the state.
  for (int k = 0; k < 3 && !pool.keepsAcceleration(); ++k) {
    const char* bytes = p.floats[kFirstAccelerationColumn + k];
    if (std::any_of(bytes, bytes + 4 * n, [](char b) { return b != 0; })) pool.keepAcceleration();
  }
  pool.keepPrevious();  // what a restored frame between ticks interpolates from
  pool.reserve(n);      // the other allocation, changing no state either
  pool.resizeForRestore(n, p.nextId, p.droppedSpawns);
  int c = 0;
  forEachFloatColumn(pool, [&](FloatColumn* column) {
    if (column != nullptr) loadLittleEndian(p.floats[c], column->data(), n);
    ++c;
  });
  loadLittleEndian(p.ids, pool.id().data(), n);
  loadLittleEndian(p.births, pool.birthTick().data(), n);
  for (const auto& [name, values] : p.attributes) {
    loadLittleEndian(values, pool.attribute(pool.findAttribute(std::string(name))).data(), n);
  }
  // Between ticks no particle is flagged; a used target may have stale flags past its old size.
  std::fill_n(pool.dead().begin(), n, std::uint8_t{0});
  if (system.springs() != nullptr) system.springs()->restore(p.springs, p.springsBroken);
  if (system.events() != nullptr) system.events()->restorePending(p.events, p.eventValues);
  system.driver().restore(p.ticksIssued, p.ticksDropped, p.ticksDue, p.remainder);
  Vec3Column velocities;
  if (p.tickStartVelocities != nullptr) {
    velocities.resize(static_cast<Eigen::Index>(n));
    for (int k = 0; k < 3; ++k)
      loadLittleEndian(p.tickStartVelocities + k * 4 * n, velocities[k].data(), n);
  }
  system.restoreClock(p.tick, p.tickStartVelocities != nullptr ? &velocities : nullptr);
}

// The file at `path` read whole and checked (magic, version, flags, length, checksum) and its
// payload parsed; throws std::runtime_error "PATH: error: ..." otherwise.
Parsed loadCheckpointFile(const std::filesystem::path& path) {
  auto file = std::make_unique<const FileBytes>(path);
  const std::string_view bytes = file->view();
  const std::size_t found = bytes.size();
  auto truncated = [&](const std::string& expected) {
    fail(path, "checkpoint is truncated (expected " + expected + " bytes, found " +
                   std::to_string(found) + ")");
  };

  // A prefix of the magic (an empty file included) is what an interrupted copy leaves: call it
  // truncated; anything else is some other file.
  if (bytes.compare(0, kCheckpointMagic.size(), kCheckpointMagic, 0,
                    std::min(found, kCheckpointMagic.size())) != 0) {
    fail(path, "not a tickfx checkpoint (it does not start with TICKFXCK)");
  }
  if (found < kFlagsOffset) truncated("at least " + std::to_string(kMinimumBytes));
  const std::uint32_t version = loadU32(bytes.data() + kVersionOffset);
  if (version != kCheckpointVersion) {
    fail(path, "checkpoint format version " + std::to_string(version) + " (this build reads " +
                   std::to_string(kCheckpointVersion) + ")");
  }
  if (found < kEffectHashOffset) truncated("at least " + std::to_string(kMinimumBytes));
  const std::uint32_t flags = loadU32(bytes.data() + kFlagsOffset);
  if ((flags & ~kKnownFlags) != 0) {
    fail(path, "checkpoint has unknown flags " + std::to_string(flags & ~kKnownFlags) +
                   " (this build reads files with flags 0 to 3)");
  }
  const std::uint64_t length = loadU64(bytes.data() + kLengthOffset);
  if (length < kMinimumBytes) {
    fail(path, "checkpoint header is damaged (file length " + std::to_string(length) +
                   ", expected at least " + std::to_string(kMinimumBytes) + ")");
  }
  if (found < length) truncated(std::to_string(length));
  if (found > length) {
    fail(path, "checkpoint is longer than its header says (expected " + std::to_string(length) +
                   " bytes, found " + std::to_string(found) + ")");
  }
  const std::string_view covered(bytes.data(), found - kTrailerBytes);
  if (piecewiseFingerprint(covered) != loadU64(bytes.data() + found - kTrailerBytes)) {
    fail(path, "checksum mismatch (the file is corrupted)");
  }
  Parsed parsed;
  try {
    parsed = parsePayload(covered.substr(kHeaderBytes), flags);
  } catch (const Malformed& m) {
    fail(path, "checkpoint is malformed (" + m.what + ")");
  }
  parsed.info.effectHash = loadU64(bytes.data() + kEffectHashOffset);
  parsed.file = std::move(file);
  return parsed;
}

// A state as a checkpoint holds it, borrowed from a system or from merged shards: what
// writeState() writes. A null float column is written as zeros (an acceleration the pool does not
// keep).
struct StateView : StateScalars {
  std::size_t size = 0;
  const float* floats[kFloatColumns] = {};
  const std::uint64_t* ids = nullptr;
  const std::uint32_t* births = nullptr;
  bool hasVelocities = false;       // tick-start velocities ...
  const float* velocities[3] = {};  // ... these (null for no rows)
  std::vector<std::pair<std::string_view, const float*>> attributes;
  std::span<const Spring> springs;
  std::uint64_t springsBroken = 0;
  std::span<const ParticleEvent> events;
  std::span<const float> eventValues;
  std::uint32_t inheritedColumns = 0;
  Shard shard;
};

std::uint32_t bitsOf(float f) {
  std::uint32_t bits = 0;
  std::memcpy(&bits, &f, 4);
  return bits;
}

// Everything but the trailer, in the layout writeCheckpoint() documents; `length` is the file's.
void writeState(const StateView& v, Writer& w, std::uint64_t length) {
  const std::size_t n = v.size;
  w.bytes(kCheckpointMagic);
  w.u32(kCheckpointVersion);
  w.u32((v.events.empty() ? 0u : kPendingEventsFlag) | (v.shard.whole() ? 0u : kShardFlag));
  w.u64(length);
  w.u64(v.info.effectHash);

  w.i64(v.stepRateHz);
  w.str(v.integrator);
  w.u64(v.maxParticles);
  w.i64(v.maxTicksPerFrame);
  w.u32(v.overrunPolicy);
  w.i64(v.tick);
  w.i64(v.ticksIssued);
  w.i64(v.ticksDropped);
  w.i64(v.ticksDue);
  w.i64(v.remainder);
  w.i64(v.info.frame);
  w.i64(v.info.elapsed);
  w.u64(n);
  w.u64(v.nextId);
  w.u64(v.droppedSpawns);
  w.u32(static_cast<std::uint32_t>(v.attributes.size()));
  const std::vector<float> zeros(n, 0.0f);
  for (const float* column : v.floats) w.column(column != nullptr ? column : zeros.data(), n);
  w.column(v.ids, n);
  w.column(v.births, n);
  w.u32(v.hasVelocities ? 1 : 0);
  if (v.hasVelocities) {
    for (const float* column : v.velocities) w.column(column, n);
  }
  for (const auto& [name, values] : v.attributes) {
    w.str(name);
    w.column(values, n);
  }
  w.u64(v.springs.size());
  w.u64(v.springsBroken);
  for (const Spring& spring : v.springs) {
    w.u64(spring.a);
    w.u64(spring.b);
    for (float value : {spring.restLength, spring.stiffness, spring.damping, spring.breakRatio})
      w.u32(bitsOf(value));
  }
  if (!v.events.empty()) {
    w.u64(v.events.size());
    w.u32(v.inheritedColumns);
    for (const ParticleEvent& e : v.events) {
      w.u64(e.parentId);
      w.u32(e.parentEmitter);
      w.u32(static_cast<std::uint32_t>(e.kind));
      w.u32(e.ordinal);
      for (const Eigen::Vector3f* vec : {&e.position, &e.velocity, &e.normal}) {
        for (int c = 0; c < 3; ++c) w.u32(bitsOf((*vec)[c]));
      }
    }
    for (const float value : v.eventValues) w.u32(bitsOf(value));
  }
  if (!v.shard.whole()) {
    w.u32(v.shard.index);
    w.u32(v.shard.count);
  }
}

// Writes the checkpoint of `v` to `path` (atomically, synced), streaming: a first pass counts
// the bytes for the header's length, the second writes them and their checksum.
void writeStateFile(const std::filesystem::path& path, const StateView& v) {
  Writer counter(nullptr);
  writeState(v, counter, 0);
  const std::uint64_t length = counter.size() + kTrailerBytes;
  writeFileAtomically(
      path,
      [&](std::ostream& out) {
        Writer w(&out);
        writeState(v, w, length);
        const std::uint64_t checksum = w.checksum();
        Writer trailer(&out);
        trailer.u64(checksum);
      },
      Durability::Synced);
}

}  // namespace

void writeCheckpoint(const std::filesystem::path& path, const ParticleSystem& system,
                     const CheckpointInfo& info) {
  const ParticlePool& pool = system.pool();
  const FixedStepDriver& driver = system.driver();
  const std::size_t n = pool.size();
  StateView v;
  v.stepRateHz = system.settings().stepRateHz;
  v.integrator = system.integrator().name();
  v.maxParticles = pool.maxParticles();
  v.maxTicksPerFrame = driver.maxTicksPerAdvance();
  v.overrunPolicy = policyCode(driver.policy());
  v.tick = system.tickCount();
  v.ticksIssued = driver.ticksIssued();
  v.ticksDropped = driver.ticksDroppedTotal();
  v.ticksDue = driver.ticksDue();
  v.remainder = driver.remainder();
  v.info = info;
  v.size = n;
  v.nextId = pool.nextId();
  v.droppedSpawns = pool.droppedSpawns();
  int c = 0;
  forEachFloatColumn(pool, [&](const FloatColumn* column) {
    v.floats[c++] = column != nullptr ? column->data() : nullptr;
  });
  // Previous positions the newest tick did not keep are written as the positions: the file is
  // the same whatever frames drove the run to this tick.
  if (!system.previousPositionsKept()) {
    for (int k = 0; k < 3; ++k) v.floats[kFirstPreviousColumn + k] = pool.position()[k].data();
  }
  v.ids = pool.id().data();
  v.births = pool.birthTick().data();
  // What render copies interpolate velocities from, so that a resumed run's caches match.
  if (const Vec3Column* velocities = system.tickStartVelocities()) {
    v.hasVelocities = true;
    for (int k = 0; k < 3; ++k) v.velocities[k] = (*velocities)[k].data();
  }
  for (std::size_t a = 0; a < pool.attributeCount(); ++a)
    v.attributes.emplace_back(pool.attributeName(a), pool.attribute(a).data());
  if (system.springs() != nullptr) {
    v.springs = system.springs()->springs();
    v.springsBroken = system.springs()->brokenCount();
  }
  if (const EventEmission* events = system.events(); events != nullptr) {
    v.events = events->pending();
    v.eventValues = events->pendingValues();
    v.inheritedColumns = static_cast<std::uint32_t>(events->inheritedColumns().size());
  }
  v.shard = system.shard();
  writeStateFile(path, v);
}

CheckpointInfo readCheckpoint(const std::filesystem::path& path, ParticleSystem& system,
                              std::uint64_t expectedEffectHash) {
  const Parsed parsed = loadCheckpointFile(path);
  if (parsed.info.effectHash != expectedEffectHash) {
    fail(path, "checkpoint was written for another effect (effect hash " +
                   hashToHex(parsed.info.effectHash) + ", expected " +
                   hashToHex(expectedEffectHash) + ")");
  }
  if (const std::optional<std::string> why = mismatch(parsed, system)) fail(path, *why);
  apply(parsed, system);
  return parsed.info;
}

namespace {

// The first field in which shard checkpoint `p` differs from `first` (of the same run: every
// shard runs the whole schedule, so all but the rows, springs and broken springs agree), or
// nothing.
std::optional<std::string> shardMismatch(const Parsed& p, const Parsed& first) {
  const auto differs = [](const char* what) { return std::optional<std::string>(what); };
  if (p.info.effectHash != first.info.effectHash) {
    return "a shard of another effect (effect hash " + hashToHex(p.info.effectHash) + ", not " +
           hashToHex(first.info.effectHash) + ")";
  }
  if (p.shard.count != first.shard.count) {
    return "a shard of " + std::to_string(p.shard.count) + " (not " +
           std::to_string(first.shard.count) + ")";
  }
  if (p.stepRateHz != first.stepRateHz || p.integrator != first.integrator ||
      p.maxParticles != first.maxParticles || p.maxTicksPerFrame != first.maxTicksPerFrame ||
      p.overrunPolicy != first.overrunPolicy) {
    return differs("other simulation settings");
  }
  if (p.tick != first.tick || p.info.frame != first.info.frame ||
      p.info.elapsed != first.info.elapsed) {
    return "another frame (frame " + std::to_string(p.info.frame) + ", tick " +
           std::to_string(p.tick) + "; not frame " + std::to_string(first.info.frame) + ", tick " +
           std::to_string(first.tick) + ")";
  }
  if (p.ticksIssued != first.ticksIssued || p.ticksDropped != first.ticksDropped ||
      p.ticksDue != first.ticksDue || p.remainder != first.remainder) {
    return differs("another driver state");
  }
  if (p.nextId != first.nextId || p.droppedSpawns != first.droppedSpawns) {
    return differs("other id counters");
  }
  bool sameAttributes = p.attributes.size() == first.attributes.size();
  for (std::size_t a = 0; sameAttributes && a < p.attributes.size(); ++a)
    sameAttributes = p.attributes[a].first == first.attributes[a].first;
  if (!sameAttributes) return differs("other attributes");
  if ((p.tickStartVelocities == nullptr) != (first.tickStartVelocities == nullptr))
    return differs("tick-start velocities where the first has none, or none where it has");
  return std::nullopt;
}

// A column of each shard (little-endian values of T), gathered in `order` into `out`.
template <typename T, typename Column>
void gather(const std::vector<Parsed>& shards, Column column,
            const std::vector<std::pair<std::uint32_t, std::uint64_t>>& order, T* out) {
  for (std::size_t i = 0; i < order.size(); ++i) {
    const Parsed& p = shards[order[i].first];
    loadLittleEndian(column(p) + order[i].second * sizeof(T), out + i, 1);
  }
}

}  // namespace

MergedCheckpoint mergeShardCheckpoints(const std::vector<std::filesystem::path>& shards,
                                       const std::filesystem::path& out) {
  if (shards.empty()) throw std::invalid_argument("mergeShardCheckpoints: no shards");
  std::vector<Parsed> parsed;
  std::vector<const std::filesystem::path*> byIndex;
  for (const std::filesystem::path& path : shards) {
    Parsed p = loadCheckpointFile(path);
    if (!p.events.empty()) fail(path, "a shard's checkpoint with pending events");
    if (!parsed.empty()) {
      if (const std::optional<std::string> why = shardMismatch(p, parsed.front())) {
        fail(path, "checkpoint is " + *why + " beside " + shards.front().string());
      }
    }
    byIndex.resize(p.shard.count, nullptr);
    if (byIndex[p.shard.index] != nullptr) {
      fail(path,
           "checkpoint of shard " + p.shard.text() + ", as is " + byIndex[p.shard.index]->string());
    }
    byIndex[p.shard.index] = &path;
    parsed.push_back(std::move(p));
  }
  const Parsed& first = parsed.front();
  for (std::uint32_t i = 0; i < first.shard.count; ++i) {
    if (byIndex[i] == nullptr) {
      fail(shards.front(), "the checkpoint of shard " + Shard{i, first.shard.count}.text() +
                               " is missing (" + std::to_string(shards.size()) + " of " +
                               std::to_string(first.shard.count) + " given)");
    }
  }

  // The rows in id order: each shard's are rising, no id is in two shards.
  std::vector<std::uint64_t> sizes;
  for (const Parsed& p : parsed) sizes.push_back(p.size);
  const auto order = mergeOrder(
      sizes,
      [&](std::size_t s, std::uint64_t row) {
        std::uint64_t id = 0;
        loadLittleEndian(parsed[s].ids + row * 8, &id, 1);
        return id;
      },
      [&](std::size_t s, std::size_t t, std::uint64_t id) {
        fail(shards[s],
             "checkpoint holds particle " + std::to_string(id) + ", as does " + shards[t].string());
      });

  // The merged rows go straight into a pool (which also gives the state hash); the shards' files
  // are let go before the merged file is serialised: at most the files and the pool, then the
  // pool and the merged file, are in memory at once.
  ParticlePool pool(static_cast<std::size_t>(first.maxParticles));
  for (const auto& [name, values] : first.attributes) pool.addAttribute(std::string(name));
  const std::size_t n = order.size();
  for (const Parsed& p : parsed) {
    for (int c = kFirstAccelerationColumn; c < kFirstAccelerationColumn + 3; ++c) {
      const char* bytes = p.floats[c];
      if (std::any_of(bytes, bytes + 4 * p.size, [](char b) { return b != 0; }))
        pool.keepAcceleration();
    }
  }
  pool.keepPrevious();
  pool.reserve(n);
  pool.resizeForRestore(n, first.nextId, first.droppedSpawns);
  int c = 0;
  forEachFloatColumn(pool, [&](FloatColumn* column) {
    if (column != nullptr) {
      gather(
          parsed, [c](const Parsed& p) { return p.floats[c]; }, order, column->data());
    }
    ++c;
  });
  gather(
      parsed, [](const Parsed& p) { return p.ids; }, order, pool.id().data());
  gather(
      parsed, [](const Parsed& p) { return p.births; }, order, pool.birthTick().data());
  for (std::size_t a = 0; a < first.attributes.size(); ++a) {
    gather(
        parsed, [a](const Parsed& p) { return p.attributes[a].second; }, order,
        pool.attribute(a).data());
  }
  Vec3Column velocities;
  const bool hasVelocities = first.tickStartVelocities != nullptr;
  if (hasVelocities) {
    velocities.resize(static_cast<Eigen::Index>(n));
    for (std::size_t k = 0; k < 3; ++k) {
      // Shard s's component k starts at k · 4 · (its rows).
      gather(
          parsed, [k](const Parsed& p) { return p.tickStartVelocities + k * 4 * p.size; }, order,
          velocities[static_cast<int>(k)].data());
    }
  }

  // Springs in the whole run's order: structures in the order of their ids (each structure's ids
  // a block of their own, all in one shard), each structure's springs in its shard's order.
  std::vector<std::uint64_t> springCounts;
  for (const Parsed& p : parsed) springCounts.push_back(p.springs.size());
  std::vector<Spring> springs;
  const auto springKey = [&](std::size_t s, std::uint64_t k) {
    const Spring& spring = parsed[s].springs[k];
    return std::min(spring.a, spring.b);
  };
  const auto noTie = [](std::size_t, std::size_t, std::uint64_t) {};  // shards share no particle
  for (const auto& [s, k] : mergeOrder(springCounts, springKey, noTie))
    springs.push_back(parsed[s].springs[k]);
  std::uint64_t springsBroken = 0;
  for (const Parsed& p : parsed) springsBroken += p.springsBroken;

  StateView v;
  static_cast<StateScalars&>(v) = first;
  const std::string integrator(first.integrator);  // first's bytes go below
  v.integrator = integrator;
  v.size = n;
  parsed.erase(parsed.begin() + 1, parsed.end());
  parsed.front().file.reset();  // the bytes the views above pointed into (copied by now)
  c = 0;
  forEachFloatColumn(pool, [&](const FloatColumn* column) {
    v.floats[c++] = column != nullptr ? column->data() : nullptr;
  });
  v.ids = pool.id().data();
  v.births = pool.birthTick().data();
  v.hasVelocities = hasVelocities;
  if (hasVelocities) {
    for (int k = 0; k < 3; ++k) v.velocities[k] = velocities[k].data();
  }
  for (std::size_t a = 0; a < pool.attributeCount(); ++a)
    v.attributes.emplace_back(pool.attributeName(a), pool.attribute(a).data());
  v.springs = springs;
  v.springsBroken = springsBroken;
  writeStateFile(out, v);
  pool.setClock(v.tick, v.stepRateHz);  // the ages the hash covers
  const MergedCheckpoint merged{stateHash(pool), v.tick, v.info};
  return merged;
}

}  // namespace tickfx::io
