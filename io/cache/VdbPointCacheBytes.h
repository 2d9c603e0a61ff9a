// The bytes of a VDB points cache, by either encoder: for the tests that hold the parallel one to
// OpenVDB's own. Internal to io/ (not installed); no OpenVDB header, like VdbPointCache.h.
#pragma once

#include <string>

#include "io/cache/FrameData.h"
#include "io/cache/VdbCacheOptions.h"
#include "io/cache/VdbPointCache.h"

namespace tickfx::io::detail {

/// Who encodes the grid into a file's bytes.
enum class VdbEncoder {
  /// encodePointsFile (VdbPointsEncoder.h): the leaves' buffers on every thread; what
  /// writeVdbPointCache writes.
  Parallel,
  /// openvdb::io::Archive::write() alone, on one thread: how tickfx wrote caches before.
  Serial,
};

/// How the grid's points are grouped into leaves and voxels.
enum class VdbGrouping {
  /// A counting sort by leaf where the leaves' bounding box is small enough to count them in a
  /// table, the sort below otherwise; what writeVdbPointCache does.
  Fastest,
  /// Every point's (leaf, voxel, row) sorted: the general way, how tickfx grouped them before.
  Sorted,
};

/// The bytes writeVdbPointCache(frame, meta, path, options) puts in its file when its grid is
/// built by `grouping` and encoded by `encoder` (the UUID stamped as it stamps it). Every
/// grouping and encoder gives the same bytes.
std::string vdbPointCacheBytes(const FrameData& frame, const VdbCacheMetadata& meta,
                               const VdbCacheOptions& options, VdbEncoder encoder,
                               VdbGrouping grouping = VdbGrouping::Fastest);

}  // namespace tickfx::io::detail
