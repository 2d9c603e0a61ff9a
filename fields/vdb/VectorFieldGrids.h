// VectorField's in-memory input and baked grids: for code that works with OpenVDB grids itself.
// Includes OpenVDB, so it stays out of the installed headers and out of every other translation
// unit.
#pragma once

#include <openvdb/openvdb.h>

#include <vector>

#include "fields/vdb/AnalyticField.h"
#include "fields/vdb/VectorField.h"

namespace tickfx {

/// The grids of a field: one, or one a frame of a sequence, vec3s or vec3d. Shared, not copied.
struct VectorField::Grids {
  std::vector<openvdb::GridBase::Ptr> grids;
};

/// The grid bakeField() writes and bakeVectorField() samples, for code that hands it to OpenVDB
/// itself (tests and benches comparing with OpenVDB's tools).
openvdb::Vec3fGrid::Ptr bakeGrid(const AnalyticField& field, const BakeSettings& settings,
                                 double time = 0.0);

}  // namespace tickfx
