// Frame caches as OpenVDB points (.vdb): what Houdini and other VDB tools read as a point cloud.
// OpenVDB's headers stay in VdbPointCache.cpp: this header includes none of them.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

#include "io/cache/FrameData.h"
#include "io/cache/VdbCacheOptions.h"
#include "io/util/AtomicFile.h"

namespace tickfx::io {

/// What a pipeline needs to know about the run that wrote a cache, stored as metadata of the
/// grid (see writeVdbPointCache for the names). The frame number, its time and the point count
/// come from the FrameData itself.
struct VdbCacheMetadata {
  std::string effectHash;       // the effect's fingerprint (file bytes and overrides), hex
  std::uint64_t seed = 0;       // the effect seed (at most 2⁶³ − 1, as effect files allow)
  std::int64_t stepRateHz = 0;  // ticks per second
  std::string integrator;       // "semi_implicit_euler", ...
  std::string tickfxVersion;    // the version of tickfx that wrote the file, "0.1.0"
};

/// What a file held besides the particles.
struct VdbCacheContents {
  /// The grid's metadata; keys absent from the file leave their field at its default.
  VdbCacheMetadata metadata;
  /// Whether each optional attribute was in the file (an absent one reads as its default).
  bool hasVelocity = false;
  bool hasId = false;
  bool hasAge = false;
  bool hasLife = false;
  bool hasMass = false;
};

/// Writes `frame` to `path` (atomically: into a temporary beside it, then renamed; an error
/// leaves no file and an existing `path` untouched) as one OpenVDB PointDataGrid named "points",
/// by default every value stored whole (OpenVDB's null codec, no quantisation, no compression; see
/// VdbCacheOptions for the others) so that it reads back bit for bit:
///   P   vec3s, positions in metres, OpenVDB's way: the voxel's index plus P, times the voxel
///       size. The voxel size is 1 m (multiplying by 1 is exact: any other size would lose the
///       low bits of some positions), each point in the voxel nearest to it, so P is the offset
///       from the voxel's centre, within ±0.5. Coordinates beyond ±2³⁰ m (and inf or nan, which
///       a blown-up simulation may reach) are kept whole in voxel 0 of that axis instead. The
///       usual reading, (voxel + P) · 1, then gives every coordinate's exact float bits except
///       the sign of a zero (−0.0 reads as +0.0); readVdbPointCache keeps that too.
///   v   vec3s, m/s;  id  int64 (the id's bits: ids of 2⁶³ and more read as negative);
///   age, life (+inf for immortal particles), mass: float, seconds, seconds and kilograms;
///   every custom attribute, float, by its name in frame.attributeNames (after the above, in
///   that order). A custom attribute named like a standard one, or not a valid OpenVDB attribute
///   name (letters, digits, '_', '|', ':'), throws std::invalid_argument.
/// Grid metadata (vdb_print -m lists it): tickfx_effect_hash (string), tickfx_seed (int64),
/// tickfx_step_rate (int64, Hz), tickfx_integrator (string), tickfx_frame (int64),
/// tickfx_time (double, seconds), tickfx_version (string), tickfx_point_count (int64).
/// The grid is built and encoded leaf by leaf in parallel (TBB; the bytes are those of OpenVDB's
/// own serial writer) and the file's bytes do not depend on the thread count. Throws WriteError
/// naming the file when it cannot be written.
void writeVdbPointCache(const FrameData& frame, const VdbCacheMetadata& meta,
                        const std::filesystem::path& path, const VdbCacheOptions& options = {},
                        Durability durability = Durability::Renamed);

/// Reads the PointDataGrid "points" of `path`: a file written by writeVdbPointCache, or any other
/// with at least a vec3s P (any codec, any linear transform). Rows come back sorted by id, which
/// is the order writeVdbPointCache was given (FrameData rows are in id order); a file without id
/// keeps OpenVDB's order (leaf by leaf, voxel by voxel, and within a voxel as written), ids being
/// then the row numbers 0, 1, .... Optional attributes: v (vec3s; absent: 0), id (int64 or int32),
/// age (absent: 0), life (absent: +inf), mass (absent: 1); every other float attribute becomes a
/// custom attribute, in the file's order, then Houdini's colour Cd (vec3s) the three custom
/// attributes Cd_r, Cd_g and Cd_b; attributes of other types are ignored. The frame number
/// and time come from tickfx_frame and tickfx_time (absent: 0). `contents`, when given, receives
/// the metadata and which attributes were present.
/// Throws std::runtime_error naming the file and the grid ("PATH: grid 'points': ...") when the
/// file is missing, is not an OpenVDB file, is truncated or corrupt, has no grid "points", the grid
/// is not a PointDataGrid, or it has no P. Every byte is checked before OpenVDB reads it (see
/// readVdbGrid): a damaged file is an exception, never an abort inside OpenVDB.
FrameData readVdbPointCache(const std::filesystem::path& path,
                            VdbCacheContents* contents = nullptr);

}  // namespace tickfx::io
