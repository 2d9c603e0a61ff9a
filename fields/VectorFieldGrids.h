// VectorField's in-memory input: for code that makes OpenVDB grids itself (baking). Includes
// OpenVDB, so it stays out of the installed headers and out of every other translation unit.
#pragma once

#include <openvdb/openvdb.h>

#include <vector>

#include "fields/VectorField.h"

namespace tickfx {

/// The grids of a field: one, or one a frame of a sequence, vec3s or vec3d. Shared, not copied.
struct VectorField::Grids {
  std::vector<openvdb::GridBase::Ptr> grids;
};

}  // namespace tickfx
