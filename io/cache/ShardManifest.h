// What a shard of a run (`tickfx run --shard I/N`) leaves in its folder beside its caches, so that
// `tickfx merge` can tell which shards belong together.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "io/cache/CacheFormat.h"
#include "io/cache/VdbCacheOptions.h"
#include "particles/Shard.h"

namespace tickfx::io {

/// DIR/shard.toml. A shard writes it last, when every one of its files is whole: a folder
/// without it holds no finished shard.
struct ShardManifest {
  std::string effect;      // the effect file as the run named it
  std::string effectHash;  // the effect's fingerprint (file bytes and overrides), 16 hex digits
  std::uint64_t seed = 0;
  std::int64_t stepRateHz = 0;
  std::string integrator;
  Shard shard;
  std::vector<CacheFormat> formats;  // what the folder holds a file (or a layer) of per frame
  VdbCacheOptions vdb;               // how its .vdb files were written
  double framesPerSecond = 24.0;     // the output rate: a USD layer's time codes per second
  std::int64_t lastFrame = 0;        // frames 1 to lastFrame are in the folder
  std::int64_t ticks = 0;            // ticks run by the last frame's end
  std::string usdaName;              // the USD layer's file name, when formats has usda
};

/// The manifest's path in `directory`.
std::filesystem::path shardManifestPath(const std::filesystem::path& directory);

/// Writes `manifest` into `directory` (atomically). Throws WriteError.
void writeShardManifest(const ShardManifest& manifest, const std::filesystem::path& directory);

/// Reads the manifest of `directory`. Throws std::runtime_error "DIR: error: ..." when the
/// folder has none ("not a finished shard's folder"), and "DIR/shard.toml:LINE:COL: error: ..."
/// for a malformed one.
ShardManifest readShardManifest(const std::filesystem::path& directory);

}  // namespace tickfx::io
