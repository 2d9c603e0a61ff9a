// Level-set colliders: a signed-distance grid (OpenVDB) that particles do not pass through.
// OpenVDB stays inside LevelSetCollider.cpp: this header includes none of it.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "fields/Collider.h"

namespace tickfx {

/// A triangle mesh (metres): what io/mesh reads from an OBJ or PLY file for a level set.
struct TriangleMesh {
  std::vector<Eigen::Vector3f> points;
  std::vector<std::array<std::uint32_t, 3>> triangles;  // indices into points
};

/// Why `mesh` cannot bound a solid, or empty when it can: no triangles, an index past the points,
/// a degenerate triangle (two equal indices), or an edge not shared by exactly two triangles
/// (the mesh is not closed).
std::string meshProblem(const TriangleMesh& mesh);

/// A level-set collider for settings.type == ColliderType::LevelSet, its grid from
/// settings.levelSet: read from the .vdb file at `path` (a float grid of any class whose
/// transform is axis-aligned with cubic voxels, checked as every .vdb file tickfx reads),
/// made from `mesh` with openvdb::tools::meshToLevelSet at voxel_size (a closed mesh: see
/// meshProblem), or baked from the analytic shape at voxel_size, 3 voxels each side of the
/// surface.
///
/// The grid's values are distances in metres, negative inside. A path is marched from its start
/// in steps of half a voxel near the surface and of half its value farther away (trilinear
/// interpolation of distances changes by at most √3 per metre, so no step skips a crossing),
/// sampled trilinearly in float; the first step that ends deeper than the margin is refined by four
/// steps of regula falsi (Illinois) to the crossing, and the contact settled on the surface along
/// the normal. A path whose bounding box misses the grid's active voxels (grown by the particles'
/// radius and a voxel) samples nothing. The normal is the grid's gradient by central differences
/// half a voxel apart.
///
/// Throws std::invalid_argument for invalid settings and std::runtime_error for a grid that
/// cannot be used (the file's message, not a float grid, a sheared or non-cubic transform, a mesh
/// that is not closed, a grid with no active voxel).
std::unique_ptr<Collider> makeLevelSetCollider(const ColliderSettings& settings,
                                               const TriangleMesh* mesh = nullptr);

/// What a level-set collider made by makeLevelSetCollider samples: its voxel edge and the world
/// box (m, in its rest pose) of its active voxels, grown by the particles' radius and a voxel.
struct LevelSetInfo {
  float voxelSize = 0.0f;
  Eigen::Vector3f lo = Eigen::Vector3f::Zero(), hi = Eigen::Vector3f::Zero();
};
/// Nothing for a collider that is not a level set.
std::optional<LevelSetInfo> levelSetInfo(const Collider& collider);

}  // namespace tickfx
