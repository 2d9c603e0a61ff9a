#include "io/cache/ShardManifest.h"

#include <toml++/toml.h>

#include <cstdio>
#include <ostream>
#include <stdexcept>
#include <system_error>

#include "io/util/AtomicFile.h"

namespace tickfx::io {
namespace {

constexpr const char* kManifestName = "shard.toml";

std::string quoted(const std::string& text) {
  std::string out = "\"";
  for (const char c : text) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

[[noreturn]] void malformed(const std::filesystem::path& path, const toml::source_region& where,
                            const std::string& what) {
  throw std::runtime_error(path.string() + ":" + std::to_string(where.begin.line) + ":" +
                           std::to_string(where.begin.column) + ": error: " + what);
}

template <typename T>
T required(const toml::table& table, const std::filesystem::path& path, const char* key) {
  const toml::node* node = table.get(key);
  if (node == nullptr) malformed(path, table.source(), std::string("no key '") + key + "'");
  const std::optional<T> value = node->value<T>();
  if (!value) malformed(path, node->source(), std::string("'") + key + "' has the wrong type");
  return *value;
}

}  // namespace

std::filesystem::path shardManifestPath(const std::filesystem::path& directory) {
  return directory / kManifestName;
}

void writeShardManifest(const ShardManifest& m, const std::filesystem::path& directory) {
  writeFileAtomically(shardManifestPath(directory), [&](std::ostream& out) {
    char fps[40];
    std::snprintf(fps, sizeof fps, "%.17g", m.framesPerSecond);
    out << "# One shard of a tickfx run: `tickfx merge` reads this beside the shard's files.\n"
        << "format_version = 1\n"
        << "effect = " << quoted(m.effect) << "\n"
        << "effect_hash = " << quoted(m.effectHash) << "\n"
        << "seed = " << static_cast<std::int64_t>(m.seed) << "\n"
        << "step_rate = " << m.stepRateHz << "\n"
        << "integrator = " << quoted(m.integrator) << "\n"
        << "shard = " << m.shard.index << "\n"
        << "shards = " << m.shard.count << "\n"
        << "formats = [";
    for (std::size_t i = 0; i < m.formats.size(); ++i)
      out << (i > 0 ? ", " : "") << quoted(std::string(cacheFormatName(m.formats[i])));
    out << "]\n"
        << "vdb_compression = " << quoted(std::string(vdbCompressionName(m.vdb.compression)))
        << "\n"
        << "vdb_positions = " << quoted(std::string(vdbPositionsName(m.vdb.positions))) << "\n"
        << "fps = " << fps << "\n"
        << "last_frame = " << m.lastFrame << "\n"
        << "ticks = " << m.ticks << "\n"
        << "usda = " << quoted(m.usdaName) << "\n";
  });
}

ShardManifest readShardManifest(const std::filesystem::path& directory) {
  const std::filesystem::path path = shardManifestPath(directory);
  std::error_code ec;
  if (!std::filesystem::is_directory(directory, ec))
    throw std::runtime_error(directory.string() + ": error: not a folder");
  if (!std::filesystem::exists(path, ec)) {
    throw std::runtime_error(directory.string() + ": error: not a finished shard's folder (no " +
                             kManifestName + ": a shard writes it when its last file is whole)");
  }
  toml::table table;
  try {
    table = toml::parse_file(path.string());
  } catch (const toml::parse_error& e) {
    malformed(path, e.source(), std::string(e.description()));
  }
  ShardManifest m;
  if (required<std::int64_t>(table, path, "format_version") != 1)
    malformed(path, table["format_version"].node()->source(), "unknown format_version");
  m.effect = required<std::string>(table, path, "effect");
  m.effectHash = required<std::string>(table, path, "effect_hash");
  m.seed = static_cast<std::uint64_t>(required<std::int64_t>(table, path, "seed"));
  m.stepRateHz = required<std::int64_t>(table, path, "step_rate");
  m.integrator = required<std::string>(table, path, "integrator");
  const std::int64_t index = required<std::int64_t>(table, path, "shard");
  const std::int64_t count = required<std::int64_t>(table, path, "shards");
  m.shard = Shard{static_cast<std::uint32_t>(index), static_cast<std::uint32_t>(count)};
  if (index < 0 || count < 1 || count > Shard::kMaxCount || m.shard.problem())
    malformed(path, table["shard"].node()->source(), "not a shard: " + m.shard.text());
  const toml::array* formats = table["formats"].as_array();
  if (formats == nullptr) malformed(path, table.source(), "no array 'formats'");
  for (const toml::node& f : *formats) {
    const std::optional<std::string> name = f.value<std::string>();
    const std::optional<CacheFormat> format = name ? cacheFormatFromName(*name) : std::nullopt;
    if (!format) malformed(path, f.source(), "unknown format");
    m.formats.push_back(*format);
  }
  const auto compression =
      vdbCompressionNamed(required<std::string>(table, path, "vdb_compression"));
  const auto positions = vdbPositionsNamed(required<std::string>(table, path, "vdb_positions"));
  if (!compression || !positions)
    malformed(path, table.source(), "unknown vdb_compression or vdb_positions");
  m.vdb = VdbCacheOptions{*compression, *positions};
  m.framesPerSecond = required<double>(table, path, "fps");
  m.lastFrame = required<std::int64_t>(table, path, "last_frame");
  m.ticks = required<std::int64_t>(table, path, "ticks");
  m.usdaName = required<std::string>(table, path, "usda");
  for (const auto& [key, node] : table) {
    static const char* const known[] = {
        "format_version", "effect", "effect_hash", "seed",    "step_rate",
        "integrator",     "shard",  "shards",      "formats", "vdb_compression",
        "vdb_positions",  "fps",    "last_frame",  "ticks",   "usda"};
    bool ok = false;
    for (const char* k : known) ok = ok || key.str() == k;
    if (!ok) malformed(path, node.source(), "unknown key '" + std::string(key.str()) + "'");
  }
  return m;
}

}  // namespace tickfx::io
