// tickfx merge: the whole run's files made of the folders of its shards (`tickfx run --shard`).
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/Commands.h"
#include "io/cache/CsvCache.h"
#include "io/cache/FrameCaches.h"
#include "io/cache/PlyCache.h"
#include "io/cache/ShardManifest.h"
#include "io/cache/ShardMerge.h"
#include "io/cache/UsdaPointsWriter.h"
#include "io/cache/UsdaReader.h"
#include "io/cache/VdbPointCache.h"
#include "io/state/Checkpoint.h"
#include "io/util/AtomicFile.h"
#include "particles/StateHash.h"

namespace tickfx::app {
namespace {

constexpr const char* kMergeHelp =
    "usage: tickfx merge SHARD_DIR... --out DIR [--hash] [--quiet]\n"
    "\n"
    "Merges the folders of every shard of a run (`tickfx run EFFECT --shard I/N`, any order) into\n"
    "DIR: each frame's caches (csv, ply, vdb), the USD layer, the checkpoints and the final\n"
    "state, each byte for byte the file the unsharded run writes. One merged frame at a time is\n"
    "in memory. Shards of other effects, seeds, step rates or shard counts, a missing shard and\n"
    "a missing frame are refused by name (exit 2).\n"
    "  --out DIR   where the merged files go\n"
    "  --hash      print 'state-hash: <16 hex digits>' and 'ticks: N': what the unsharded run's\n"
    "              --hash prints\n"
    "  --quiet     no summary\n";

// A refusal of the shards given: bad input, exit 2.
struct Refusal : std::runtime_error {
  using std::runtime_error::runtime_error;
};

[[noreturn]] void refuse(const std::filesystem::path& dir, const std::string& what) {
  throw Refusal(dir.string() + ": error: " + what);
}

// The first way manifest `m` (of `dir`) does not belong with `first` (of `firstDir`), if any.
void checkBelongs(const io::ShardManifest& m, const std::filesystem::path& dir,
                  const io::ShardManifest& first, const std::filesystem::path& firstDir) {
  const std::string beside = " (" + firstDir.string() + " has ";
  if (m.effectHash != first.effectHash) {
    refuse(dir, "a shard of another effect: effect hash " + m.effectHash + beside +
                    first.effectHash + ")");
  }
  if (m.seed != first.seed) {
    refuse(dir, "a shard of another seed: " + std::to_string(m.seed) + beside +
                    std::to_string(first.seed) + ")");
  }
  if (m.stepRateHz != first.stepRateHz || m.integrator != first.integrator) {
    refuse(dir, "a shard of another step rate or integrator: " + std::to_string(m.stepRateHz) +
                    " Hz, " + m.integrator + beside + std::to_string(first.stepRateHz) + " Hz, " +
                    first.integrator + ")");
  }
  if (m.shard.count != first.shard.count) {
    refuse(dir, "shard " + m.shard.text() + " of a run in " + std::to_string(m.shard.count) +
                    " shards" + beside + "shard " + first.shard.text() + ")");
  }
  if (m.lastFrame != first.lastFrame || m.ticks != first.ticks ||
      m.framesPerSecond != first.framesPerSecond) {
    refuse(dir, "a shard of another length: " + std::to_string(m.lastFrame) + " frames, " +
                    std::to_string(m.ticks) + " ticks" + beside + std::to_string(first.lastFrame) +
                    " frames, " + std::to_string(first.ticks) + " ticks)");
  }
  if (m.formats != first.formats || m.vdb.compression != first.vdb.compression ||
      m.vdb.positions != first.vdb.positions || m.usdaName != first.usdaName) {
    refuse(dir, "a shard written in other formats or VDB options than " + firstDir.string());
  }
}

// The shards' folders in shard order, every shard once.
std::vector<std::filesystem::path> shardsInOrder(const std::vector<std::string>& dirs,
                                                 std::vector<io::ShardManifest>& manifests) {
  for (const std::string& dir : dirs) {
    try {
      manifests.push_back(io::readShardManifest(dir));
    } catch (const std::runtime_error& e) {
      throw Refusal(e.what());
    }
    if (manifests.size() > 1) checkBelongs(manifests.back(), dir, manifests.front(), dirs[0]);
  }
  const std::uint32_t count = manifests.front().shard.count;
  std::vector<std::filesystem::path> ordered(count);
  for (std::size_t i = 0; i < dirs.size(); ++i) {
    std::filesystem::path& slot = ordered[manifests[i].shard.index];
    if (!slot.empty())
      refuse(dirs[i], "shard " + manifests[i].shard.text() + ", as is " + slot.string());
    slot = dirs[i];
  }
  for (std::uint32_t i = 0; i < count; ++i) {
    if (ordered[i].empty()) {
      refuse(dirs[0], "shard " + Shard{i, count}.text() + " is missing (" +
                          std::to_string(dirs.size()) + " of " + std::to_string(count) +
                          " shard folders given)");
    }
  }
  std::vector<io::ShardManifest> byIndex(count);
  for (std::size_t i = 0; i < dirs.size(); ++i) byIndex[manifests[i].shard.index] = manifests[i];
  manifests = std::move(byIndex);
  return ordered;
}

// Frame `frame` of one format, each shard's file read, merged and written to `out`.
void mergeFrame(const std::vector<std::filesystem::path>& shards, const io::ShardManifest& m,
                io::CacheFormat format, std::int64_t frame, const std::filesystem::path& out) {
  const std::string_view extension = io::cacheFormatName(format);
  std::vector<io::FrameData> frames;
  std::vector<std::filesystem::path> files;
  io::VdbCacheContents contents;
  for (std::size_t s = 0; s < shards.size(); ++s) {
    const std::filesystem::path file = io::cacheFilePath(shards[s], frame, extension);
    std::error_code ec;
    if (!std::filesystem::exists(file, ec))
      refuse(file, "missing (frame " + std::to_string(frame) + " of shard " +
                       Shard{static_cast<std::uint32_t>(s), m.shard.count}.text() + ")");
    try {
      if (format == io::CacheFormat::Csv) frames.push_back(io::readCsvCache(file));
      if (format == io::CacheFormat::Ply) frames.push_back(io::readPlyCache(file));
      if (format == io::CacheFormat::Vdb)
        frames.push_back(io::readVdbPointCache(file, s == 0 ? &contents : nullptr));
      frames.back().frame = frame;
    } catch (const std::runtime_error& e) {
      throw Refusal(e.what());
    }
    files.push_back(file);
  }
  io::FrameData merged;
  try {
    merged = io::mergeShardFrames(frames, files);
  } catch (const std::runtime_error& e) {
    throw Refusal(e.what());
  }
  frames.clear();
  io::CacheTargets targets;
  targets.directory = out;
  targets.formats = {format};
  targets.vdbMetadata = contents.metadata;
  targets.vdbOptions = m.vdb;
  io::writeFrameCaches(merged, targets);
}

void mergeUsda(const std::vector<std::filesystem::path>& shards, const io::ShardManifest& m,
               const std::filesystem::path& out) {
  io::UsdaPointsWriter writer(out / m.usdaName,
                              io::UsdaLayerSettings{m.framesPerSecond, "particles"});
  for (std::int64_t f = 1; f <= m.lastFrame; ++f) {
    std::vector<io::FrameData> frames;
    std::vector<std::filesystem::path> files;
    for (const std::filesystem::path& dir : shards) {
      try {
        frames.push_back(io::readUsdaFrame(dir / m.usdaName, f));
      } catch (const std::runtime_error& e) {
        throw Refusal(e.what());
      }
      files.push_back(dir / m.usdaName);
    }
    writer.write(io::mergeShardFrames(frames, files));
  }
  writer.finish();
}

// The checkpoint names (checkpoint_NNNNNN.tfxc) in `dir`, sorted.
std::vector<std::string> checkpointNames(const std::filesystem::path& dir) {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("checkpoint_", 0) == 0 && entry.path().extension() == ".tfxc")
      names.push_back(name);
  }
  std::sort(names.begin(), names.end());
  return names;
}

io::MergedCheckpoint mergeCheckpoint(const std::vector<std::filesystem::path>& shards,
                                     const std::string& name, const std::filesystem::path& out) {
  std::vector<std::filesystem::path> files;
  for (const std::filesystem::path& dir : shards) files.push_back(dir / name);
  try {
    return io::mergeShardCheckpoints(files, out / name);
  } catch (const io::WriteError&) {
    throw;
  } catch (const std::runtime_error& e) {
    throw Refusal(e.what());
  }
}

}  // namespace

int mergeCommand(Arguments& args) {
  if (args.flag("--help")) {
    std::fputs(kMergeHelp, stdout);
    return kExitOk;
  }
  const std::optional<std::string> out = args.value("--out");
  const bool printHash = args.flag("--hash");
  const bool quiet = args.flag("--quiet");
  const std::vector<std::string> dirs = args.positionalList("one or more shard folders");
  if (!out) throw UsageError("merge: --out DIR is required");
  const auto start = std::chrono::steady_clock::now();
  try {
    std::vector<io::ShardManifest> manifests;
    const std::vector<std::filesystem::path> shards = shardsInOrder(dirs, manifests);
    const io::ShardManifest& m = manifests.front();
    for (const std::filesystem::path& dir : shards) {
      std::error_code ec;
      if (std::filesystem::equivalent(dir, *out, ec))
        refuse(*out, "--out is one of the shard folders");
    }
    std::filesystem::create_directories(*out);
    for (std::int64_t f = 1; f <= m.lastFrame; ++f) {
      for (const io::CacheFormat format : m.formats) {
        if (format != io::CacheFormat::Usda) mergeFrame(shards, m, format, f, *out);
      }
    }
    if (!m.usdaName.empty() && m.lastFrame >= 1) mergeUsda(shards, m, *out);
    const std::vector<std::string> checkpoints = checkpointNames(shards.front());
    for (const std::string& name : checkpoints) mergeCheckpoint(shards, name, *out);
    const io::MergedCheckpoint last = mergeCheckpoint(shards, "final.tfxc", *out);
    if (!quiet) {
      const double seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      std::printf(
          "%s: %u shards merged into %s: frames 1 to %lld, %zu checkpoints and the final "
          "state (%.3f s)\n",
          m.effect.c_str(), m.shard.count, out->c_str(), static_cast<long long>(m.lastFrame),
          checkpoints.size(), seconds);
    }
    if (printHash) {
      std::printf("state-hash: %s\n", hashToHex(last.stateHash).c_str());
      std::printf("ticks: %lld\n", static_cast<long long>(last.ticks));
    }
  } catch (const Refusal& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return kExitUsage;
  }
  return kExitOk;
}

}  // namespace tickfx::app
