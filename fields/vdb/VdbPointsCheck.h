// Checking a PointDataGrid's buffers the way OpenVDB 10 reads them: points::PointDataLeafNode's
// passes over the leaves, each leaf's AttributeSet::Descriptor and points::TypedAttributeArray
// metadata, the attribute pages of compression::PagedInputStream, and the voxel offsets. Internal
// to tickfx_vdb (VdbArchiveCheck.cpp uses it).
#pragma once

#include <vector>

#include "fields/vdb/VdbCheckReader.h"
#include "fields/vdb/VdbTreeCheck.h"

namespace tickfx::vdbcheck {

/// Grid::readBuffers of a PointDataGrid: a pass count, then every leaf once per pass (the voxel
/// buffer sizes, the descriptors and array metadata, the paged arrays' page headers, the voxels,
/// the arrays' contents). `leaves` are the leaves' value masks as the tree's topology gave them.
void checkPointBuffers(Cursor& in, const std::vector<LeafMask>& leaves);

}  // namespace tickfx::vdbcheck
