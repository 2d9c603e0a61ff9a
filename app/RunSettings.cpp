#include "app/RunSettings.h"

#include <cinttypes>
#include <cstdint>
#include <cstdio>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "io/cache/VdbCacheOptions.h"
#include "io/effect/EffectSettings.h"
#include "particles/StateHash.h"

namespace tickfx::app {
namespace {

std::vector<io::CacheFormat> parseFormats(const std::string& text) {
  std::vector<io::CacheFormat> formats;
  if (text == "none") return formats;
  std::stringstream list(text);
  std::string name;
  while (std::getline(list, name, ',')) {
    const std::optional<io::CacheFormat> f = io::cacheFormatFromName(name);
    if (!f) {
      throw UsageError("run: --format: unknown format '" + name +
                       "' (expected csv, ply, vdb, usda or none)");
    }
    formats.push_back(*f);
  }
  if (formats.empty())
    throw UsageError("run: --format: empty list (expected csv, ply, vdb, usda or none)");
  return formats;
}

// The frame options that cannot go together.
void checkFrameOptions(const RunArguments& a) {
  if (a.seconds && a.frames) throw UsageError("run: give --seconds or --frames, not both");
  if (a.jitter && a.frameTimes) throw UsageError("run: give --jitter or --frame-times, not both");
  if ((a.jitter || a.frameTimes) && a.fps)
    throw UsageError("run: --fps does not go with --jitter or --frame-times");
  if (a.frameTimes && (a.seconds || a.frames))
    throw UsageError("run: --frame-times sets the length; drop --seconds/--frames");
  if (a.jitter && a.frames)
    throw UsageError("run: --jitter needs a length in --seconds, not --frames");
}

// The run's length: --seconds, --frames at `rate`, or the effect's [output] length.
Flicks runLength(const io::OutputSettings& output, const RunArguments& a, FrameRate rate) {
  if (a.seconds) {
    return flicksFromSeconds(parseNumber(*a.seconds, "run: --seconds", 0.0, io::kMaxRunSeconds));
  }
  if (a.frames) {
    const long long count = parseInteger(*a.frames, "run: --frames", 0, io::kMaxRunFrames);
    return lengthOfFrames(rate, count, "run: --frames");
  }
  return lengthOfFrames(output.fps, output.frameCount(), "output length");
}

// The run's length comes from the effect (or --seconds / --frames), whatever the frame rate:
// --fps only says how that length is cut into frames.
FramePlan planFrames(const io::OutputSettings& output, const RunArguments& a) {
  checkFrameOptions(a);
  if (a.frameTimes) {
    return {FrameSchedule::recorded(readFrameTimes(*a.frameTimes)),
            "frame times from " + *a.frameTimes};
  }
  FrameRate rate = output.fps;
  if (a.fps) {
    try {
      rate = parseFrameRate(*a.fps);
    } catch (const std::invalid_argument& e) {
      throw UsageError(std::string("run: --fps: ") + e.what());
    }
  }
  const Flicks total = runLength(output, a, rate);
  if (a.jitter) {
    const auto seed =
        static_cast<std::uint64_t>(parseInteger(*a.jitter, "run: --jitter", 0, INT64_MAX));
    return {FrameSchedule::jittered(seed, total), "jittered frames (seed " + *a.jitter + ")"};
  }
  const std::string rateText =
      std::to_string(rate.numerator) +
      (rate.denominator == 1 ? "" : "/" + std::to_string(rate.denominator));
  return {FrameSchedule::fixedRate(rate, total), "at " + rateText + " fps"};
}

// A --vdb-* option's value, by the names VdbCacheOptions gives.
template <typename Named>
auto parseVdbChoice(const std::string& option, const std::string& value,
                    const std::vector<std::string>& names, Named named) {
  const auto choice = named(value);
  if (!choice) {
    throw UsageError("run: " + option + ": unknown value '" + value + "' (expected " +
                     joinWords(names, " or ") + ")");
  }
  return *choice;
}

// Where the caches go and how: the effect's [output] table, as the options change it.
io::CacheTargets cacheTargets(const RunArguments& a, const io::LoadResult& load,
                              std::vector<io::CacheFormat> formats) {
  const io::EffectSettings& effect = *load.effect;
  io::CacheTargets targets;
  targets.directory = a.out ? *a.out : effect.output.directory;
  targets.formats = std::move(formats);
  // What a VDB cache records of the run, for the pipeline that reads it.
  targets.vdbMetadata = io::VdbCacheMetadata{hashToHex(load.fingerprint), effect.simulation.seed,
                                             effect.simulation.stepRateHz,
                                             effect.simulation.integrator, TICKFX_VERSION};
  targets.vdbOptions = effect.output.vdb;
  if (a.vdbCompression) {
    targets.vdbOptions.compression = parseVdbChoice(
        "--vdb-compression", *a.vdbCompression, io::vdbCompressionNames(), io::vdbCompressionNamed);
  }
  if (a.vdbPositions) {
    targets.vdbOptions.positions = parseVdbChoice("--vdb-positions", *a.vdbPositions,
                                                  io::vdbPositionsNames(), io::vdbPositionsNamed);
  }
  targets.durability = a.durable ? io::Durability::Synced : io::Durability::Renamed;
  return targets;
}

}  // namespace

RunArguments readRunArguments(Arguments& args) {
  RunArguments a;
  a.overrides = args.values("--set");
  a.seconds = args.value("--seconds");
  a.frames = args.value("--frames");
  a.fps = args.value("--fps");
  a.jitter = args.value("--jitter");
  a.frameTimes = args.value("--frame-times");
  a.out = args.value("--out");
  a.format = args.value("--format");
  a.dump = args.value("--dump");
  a.trace = args.value("--trace");
  a.checkpointEvery = args.value("--checkpoint-every");
  a.checkpointDir = args.value("--checkpoint-dir");
  a.resume = args.value("--resume");
  a.threads = args.value("--threads");
  a.vdbCompression = args.value("--vdb-compression");
  a.vdbPositions = args.value("--vdb-positions");
  a.shard = args.value("--shard");
  a.durable = args.flag("--durable");
  a.overlap = !args.flag("--no-overlap");
  a.printHash = args.flag("--hash");
  a.quiet = args.flag("--quiet");
  a.profile = args.flag("--profile");
  a.effectPath = args.positionals(1, "one effect file: tickfx run EFFECT.toml")[0];
  return a;
}

// The checks run in a fixed order: formats, threads, frames, checkpoints, then the VDB options
// (a request with several mistakes is told of the first).
std::optional<RunSettings> resolveRunSettings(const RunArguments& a, const io::LoadResult& load) {
  const io::EffectSettings& effect = *load.effect;
  std::vector<io::CacheFormat> formats = a.format ? parseFormats(*a.format) : effect.output.formats;
  std::optional<int> threads;
  if (a.threads) {
    threads = static_cast<int>(parseInteger(*a.threads, "run: --threads", 0, io::kMaxThreads));
  }
  std::optional<FramePlan> frames;
  try {
    frames.emplace(planFrames(effect.output, a));
  } catch (const std::runtime_error& e) {
    if (dynamic_cast<const UsageError*>(&e) != nullptr) throw;
    std::fprintf(stderr, "%s\n", e.what());
    return std::nullopt;
  }
  std::int64_t every = 0;
  if (a.checkpointEvery)
    every = parseInteger(*a.checkpointEvery, "run: --checkpoint-every", 1, 1'000'000'000);
  if (a.checkpointDir && !a.checkpointEvery)
    throw UsageError("run: --checkpoint-dir needs --checkpoint-every");
  std::optional<Shard> shard;
  if (a.shard) {
    try {
      shard = Shard::parse(*a.shard);
    } catch (const std::invalid_argument& e) {
      throw UsageError(std::string("run: --shard: ") + e.what());
    }
  }
  io::CacheTargets caches = cacheTargets(a, load, std::move(formats));
  // A shard's files go to a folder of their own unless --out names one.
  if (shard && !a.out) {
    caches.directory /=
        "shard_" + std::to_string(shard->index) + "_of_" + std::to_string(shard->count);
  }
  FrameRate rate = effect.output.fps;
  if (a.fps) rate = parseFrameRate(*a.fps);  // planFrames() took it
  std::filesystem::path checkpointDir =
      a.checkpointDir ? std::filesystem::path(*a.checkpointDir) : caches.directory;
  return RunSettings{.effectPath = a.effectPath,
                     .frames = std::move(*frames),
                     .threads = threads,
                     .caches = std::move(caches),
                     .checkpointEvery = every,
                     .checkpointDir = std::move(checkpointDir),
                     .resume = a.resume,
                     .dump = a.dump,
                     .trace = a.trace,
                     .overlap = a.overlap,
                     .printHash = a.printHash,
                     .quiet = a.quiet,
                     .profile = a.profile,
                     .shard = shard,
                     .framesPerSecond = static_cast<double>(rate.numerator) /
                                        static_cast<double>(rate.denominator)};
}

std::filesystem::path RunSettings::usdaPath() const {
  return caches.directory / (std::filesystem::path(effectPath).stem().string() + ".usda");
}

std::filesystem::path RunSettings::finalStatePath() const {
  return caches.directory / "final.tfxc";
}

std::filesystem::path RunSettings::checkpointPath(std::int64_t frame) const {
  char name[64];
  std::snprintf(name, sizeof name, "checkpoint_%06" PRId64 ".tfxc", frame);
  return checkpointDir / name;
}

}  // namespace tickfx::app
