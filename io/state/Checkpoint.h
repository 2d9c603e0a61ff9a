// Checkpoints: the whole simulation state in one file, so that a run can stop and resume and
// still reach the state hash of the uninterrupted run.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "io/util/Fingerprint.h"
#include "particles/Clock.h"
#include "particles/ParticleSystem.h"

namespace tickfx::io {

/// What the caller stores beside the simulation state and gets back on resume.
struct CheckpointInfo {
  /// Fingerprint of the effect (file bytes and overrides, see fingerprint()), computed by the
  /// caller; a checkpoint is only ever read back into the effect it was written for.
  std::uint64_t effectHash = 0;
  /// Frames completed when the checkpoint was written.
  std::int64_t frame = 0;
  /// Flicks of frame time fed to the driver so far.
  Flicks elapsed = 0;
};

/// The format version this build writes and the only one it reads. Version 3 no longer stores
/// ages and inverse masses (worked out from birth ticks and masses) and narrows birth ticks to 32
/// bits; version 4 has the same layout with a checksum computed in parallel pieces
/// (piecewiseFingerprint()). An earlier file is refused by its version ("checkpoint format
/// version 3 (this build reads 4)").
inline constexpr std::uint32_t kCheckpointVersion = 4;

/// Writes the state of `system` (after its last completed tick) and `info` to `path`.
///
/// The file appears whole or not at all, and is on the disk before this returns
/// (io::writeFileAtomically with Durability::Synced: after a crash or a power loss `path` holds
/// the old checkpoint or this one, whole). When writing fails, an existing `path` is left as it
/// was and no temporary stays behind; throws io::WriteError "PATH: error: cannot write (REASON)".
///
/// Layout, version 4, every integer little-endian, floats as their IEEE-754 bits:
///
///     header   "TICKFXCK"  u32 version  u32 flags  u64 file length  u64 effect hash
///     payload  i64 step rate (Hz)   str integrator   u64 max particles
///              i64 max ticks per frame   u32 overrun policy (0 drop excess, 1 fall behind)
///              i64 tick count   i64 ticks issued   i64 ticks dropped   i64 ticks due
///              i64 driver remainder
///              i64 frame   i64 elapsed (flicks)
///              u64 particle count n   u64 next id   u64 dropped spawns   u32 attribute count
///              f32[n] × 14: position, velocity, previous position, acceleration (x, y, z each),
///                           lifetime, mass
///              u64[n] id   u32[n] birth tick
///              u32 1 with f32[n] × 3: velocity at the start of the newest tick (x, y, z; what
///                  render copies interpolate from), or u32 0 without
///              per attribute: str name, f32[n] values
///              u64 spring count s   u64 springs broken so far
///              s × (u64 id a, u64 id b, f32 rest length, f32 stiffness, f32 damping, f32 break
///              ratio)
///              with flag 1 (sub-emitters' events wait for the next tick; else nothing):
///              u64 event count e (> 0)   u32 inherited columns k
///              e × (u64 parent id, u32 parent emitter, u32 kind (1 birth, 2 death, 3 collision),
///                   u32 ordinal, f32 × 9: position, velocity, normal)
///              f32[e · k]: each event's inherited values
///              with flag 2 (one shard's state, particles/Shard.h; else nothing):
///              u32 shard index   u32 shard count
///     trailer  u64 checksum: piecewiseFingerprint() of every byte before it
///
/// where str is a u32 byte count followed by that many UTF-8 bytes.
void writeCheckpoint(const std::filesystem::path& path, const ParticleSystem& system,
                     const CheckpointInfo& info);

/// Reads the checkpoint at `path` into `system` and returns the stored info.
///
/// The whole file is read and verified before `system` is touched: magic, version, length,
/// checksum, `expectedEffectHash`, then that `system` was built from matching settings (step
/// rate, integrator, max particles, max ticks per frame, overrun policy, the same attribute
/// names, springs only where the effect has structures). Only then are the pool (every column and
/// attribute, size, next id, dropped spawns), the spring network, the driver (ticks issued, ticks
/// dropped, ticks due, remainder), the tick count and the tick-start velocities replaced, so
/// `system` continues, and renders, exactly as the system that wrote the file would have.
/// (Version 1 files, which lack the driver's ticks due, are refused.)
///
/// On any refusal throws std::runtime_error "PATH: error: what (expected)", e.g.
/// "ckpt.bin: error: checkpoint is truncated (expected 5120 bytes, found 1000)", and `system` is
/// left exactly as it was.
CheckpointInfo readCheckpoint(const std::filesystem::path& path, ParticleSystem& system,
                              std::uint64_t expectedEffectHash);

/// What mergeShardCheckpoints() made.
struct MergedCheckpoint {
  std::uint64_t stateHash = 0;  // stateHash() of the merged state: what the whole run prints
  std::int64_t ticks = 0;       // its tick count
  CheckpointInfo info;          // the frame and time the shards' checkpoints were written at
};

/// Merges the checkpoints that every shard of a run (`tickfx run --shard I/N`) wrote at the same
/// frame, one a shard in any order, into `out`: byte for byte the checkpoint the unsharded run
/// writes there (rows merged by id, the shards' springs in the whole run's order, their broken
/// springs summed). Streams nothing: memory holds every shard's file and the merged state.
/// Throws std::runtime_error "PATH: error: ..." naming the file for a checkpoint that does not
/// read (as readCheckpoint), is not a shard's, is of another effect, shard count, frame or
/// settings than the first, repeats a shard or a particle, or when a shard is missing.
MergedCheckpoint mergeShardCheckpoints(const std::vector<std::filesystem::path>& shards,
                                       const std::filesystem::path& out);

}  // namespace tickfx::io
