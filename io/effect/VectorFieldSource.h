// Where the grids of a `vector_field` force come from: its .vdb file (or {frame} sequence), or
// its `bake` table baked in memory. The builder (run) and the lint (check) load fields through
// here; `tickfx bake-field` makes its analytic fields with the same functions.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <string>

#include "fields/vdb/AnalyticField.h"
#include "fields/vdb/VectorField.h"
#include "io/effect/EffectSettings.h"

namespace tickfx::io {

/// The most voxels a bake may hold over all its frames: 10⁸ vec3s voxels are about 1.2 GB of
/// values, and baking them takes minutes. Effect files and `tickfx bake-field` refuse more.
inline constexpr double kMaxBakedVoxels = 1e8;
/// Limits an effect file's vector_field and `tickfx bake-field` share: frame numbers of a
/// sequence within ±kMaxFieldFrameNumber, at most kMaxFieldFrames frames, and curl noise of at
/// most kMaxCurlOctaves octaves.
inline constexpr std::int64_t kMaxFieldFrameNumber = 1'000'000;
inline constexpr std::int64_t kMaxFieldFrames = 10'000;
inline constexpr std::int64_t kMaxCurlOctaves = 16;
/// The largest |bound| / voxel_size a bake accepts: voxel indices must fit OpenVDB's 32-bit
/// coordinates (2³¹ ≈ 2.1e9) with room to spare.
inline constexpr double kMaxBakedIndex = 1e9;

/// The size of a bake of `frames` frames, and the first of its limits it breaks (checked in this
/// order: voxel indices past kMaxBakedIndex, a box holding no voxel centre, more than
/// kMaxBakedVoxels over all frames). Effect files and `tickfx bake-field` word the problem their
/// own way (keys or options) from these figures.
struct BakeSize {
  enum class Problem { None, IndexReach, EmptyBox, TooManyVoxels };
  Problem problem = Problem::None;
  double reachVoxels = 0.0;   // ⌈largest |bound| / voxel size⌉
  double minVoxelSize = 0.0;  // metres: the voxel size that keeps the bounds within the indices
  double perFrame = 0.0;      // voxels a frame
  double total = 0.0;         // voxels over all frames
};
BakeSize measureBake(const FieldBakeSettings& bake, std::int64_t frames);

/// The analytic field `bake` describes (its kind's parameters). Throws std::invalid_argument as
/// AnalyticField does (analyticFieldProblems): settings from parseEffect() never are.
AnalyticField analyticField(const FieldBakeSettings& bake);

/// What the analytic field `bake` describes refuses (AnalyticField::validateVortex and the
/// others, for its kind's parameters), keyed within the bake table ("axis", "gradient"): empty
/// when analyticField(bake) accepts it.
SettingProblems analyticFieldProblems(const FieldBakeSettings& bake);

/// Where and how `bake` is baked, under grid name `gridName` (values rounded to float once).
BakeSettings bakeSettings(const FieldBakeSettings& bake, const std::string& gridName = "vel");

/// The VectorField of one vector_field force: every frame of `field.path` loaded now (the caller
/// owns the result), or `field.bake` baked in memory (one grid, or one a frame of a sequence, frame
/// f at (f − firstFrame)/fps s), with the same bits a baked file would give. Throws
/// std::runtime_error naming the file and the grid when a file cannot be read ("PATH: grid 'vel':
/// no such file", see VectorField).
std::unique_ptr<VectorField> loadVectorField(const VectorFieldSettings& field);

}  // namespace tickfx::io
