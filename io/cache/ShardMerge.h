// Merging the frames of a run's shards (`tickfx run --shard I/N`) into the whole run's frame.
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

#include "io/cache/FrameData.h"

namespace tickfx::io {

/// The frame made of `shards` (the same frame of each shard of a run, in any order): every row of
/// every shard, in id order, which is the whole run's frame row for row and bit for bit (a
/// shard's rows are its own rows of the whole run, in id order). Throws std::runtime_error naming
/// `sources[i]` (the file shard i came from) when the shards' frame numbers, times or attribute
/// names differ, or two shards hold the same id.
FrameData mergeShardFrames(const std::vector<FrameData>& shards,
                           const std::vector<std::filesystem::path>& sources);

}  // namespace tickfx::io
