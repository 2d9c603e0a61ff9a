// Shards: which particles a run simulates when a run is split over processes or machines.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

namespace tickfx {

/// Shard `index` of `count` (0 ≤ index < count): the particles this run simulates. Every
/// particle's history is a pure function of (effect, seed, emitter, serial), so shards simulate
/// apart and their rows, merged by id, are the unsharded run's bit for bit. The whole run is
/// shard 0 of 1.
///
/// The partition, fixed so that any process computes it alone:
///   - the particle of serial s of emitter e belongs to shard (s + e) mod count: round robin
///     within each emitter, every emitter starting at another shard, so that shards stay within
///     one particle of each other per emitter at every tick;
///   - every particle of structure k (a rope, cloth, a cluster) belongs to shard k mod count: a
///     structure's springs never join two shards.
/// Ids are the unsharded run's: a shard counts every particle of the emission schedule (exact
/// integer arithmetic) and hands out ids to its own only.
struct Shard {
  std::uint32_t index = 0;
  std::uint32_t count = 1;

  static constexpr std::uint32_t kMaxCount = 65536;

  bool whole() const { return count == 1; }
  /// The shard of serial `serial` of emitter `emitter`.
  std::uint32_t ownerOfSerial(std::uint32_t emitter, std::uint64_t serial) const {
    return static_cast<std::uint32_t>((serial + emitter) % count);
  }
  /// The shard of the particles of structure `structure` (its index among the effect's).
  std::uint32_t ownerOfStructure(std::size_t structure) const {
    return static_cast<std::uint32_t>(structure % count);
  }
  /// The first serial at or after `serial` that emitter `emitter` gives this shard.
  std::uint64_t firstOwnedSerial(std::uint32_t emitter, std::uint64_t serial) const {
    const std::uint64_t behind = (serial + emitter) % count;
    return serial + (index + count - behind) % count;
  }

  /// Why this is not a shard ("index 3 is not below the count 3"), or nothing.
  std::optional<std::string> problem() const;
  /// "I/N", as `tickfx run --shard` takes it.
  std::string text() const;
  /// Parses "I/N" (I and N whole numbers, I < N ≤ kMaxCount); throws std::invalid_argument
  /// saying what is wrong.
  static Shard parse(const std::string& text);
};

}  // namespace tickfx
