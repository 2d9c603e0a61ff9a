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

/// The bytes writeVdbPointCache(frame, meta, path, options) puts in its file when its grid is
/// encoded by `encoder` (the UUID stamped as it stamps it). Both encoders give the same bytes.
std::string vdbPointCacheBytes(const FrameData& frame, const VdbCacheMetadata& meta,
                               const VdbCacheOptions& options, VdbEncoder encoder);

}  // namespace tickfx::io::detail
