#include "io/effect/EffectParser.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

#include <toml++/toml.h>

#include "integrators/Integrator.h"
#include "io/cache/CsvCache.h"
#include "io/cache/VdbPointCache.h"
#include "io/effect/EditDistance.h"
#include "io/effect/EffectBuilder.h"
#include "io/effect/ParseEmitters.h"
#include "io/effect/ParseForces.h"
#include "io/effect/ParseVectorFields.h"
#include "io/effect/SettingOverrides.h"
#include "io/effect/TableReader.h"
#include "io/effect/VectorFieldSource.h"
#include "io/util/Fingerprint.h"

#if !TOML_EXCEPTIONS
#error "tickfx_io reads parse errors from toml::parse_error: build toml++ with exceptions"
#endif

namespace tickfx::io {
namespace detail {
namespace {

constexpr std::int64_t kMaxStepRate = 1'000'000;
constexpr std::int64_t kMaxParticles = 1'000'000'000;
constexpr std::int64_t kMaxTicksPerFrame = 100'000;
constexpr std::size_t kMaxEntries = 10'000;  // emitters, forces
constexpr std::int64_t kMaxFrameRatePart = 1'000'000;

const std::vector<std::string> kOverrunPolicies = {"drop", "fall_behind"};
const std::vector<std::string> kCacheFormats = [] {
  std::vector<std::string> names;
  for (const CacheFormat f : kCacheFormatList) names.emplace_back(cacheFormatName(f));
  return names;
}();

// ---- the sections of a version-1 document ----------------------------------------------------

void readSimulation(Context& cx, const toml::table& table, SystemSettings& s) {
  TableReader r(cx, table, "simulation");
  r.integer("step_rate", s.stepRateHz, "ticks per second (Hz), an integer from 1 to 1000000", 1,
            kMaxStepRate, /*required=*/true);
  r.choice("integrator", s.integrator, integratorNames(), "integrator");
  r.integer("seed", s.seed, "an integer from 0 to 9223372036854775807", 0,
            std::numeric_limits<std::int64_t>::max());
  r.integer("max_particles", s.maxParticles, "an integer from 1 to 1000000000", 1, kMaxParticles);
  r.integer("max_ticks_per_frame", s.maxTicksPerFrame, "an integer from 1 to 100000", 1,
            kMaxTicksPerFrame);
  std::string overrun;
  if (r.choice("overrun", overrun, kOverrunPolicies, "overrun policy")) {
    s.overrunPolicy = overrun == "drop" ? OverrunPolicy::DropExcess : OverrunPolicy::FallBehind;
  }
  r.integer("threads", s.threads, "worker threads, an integer from 0 (all cores) to 1024", 0,
            kMaxThreads);
  std::string nonfinite;
  if (r.choice("nonfinite", nonfinite, nonfinitePolicyNames(), "nonfinite policy")) {
    s.nonfinite = nonfinitePolicyNamed(nonfinite);
  }
  r.finish();
}

// "30000/1001" or "24" as a frame rate.
std::optional<FrameRate> parseRatio(std::string_view text) {
  const auto readPart = [](std::string_view part) -> std::optional<std::int64_t> {
    std::int64_t v = 0;
    const auto [end, ec] = std::from_chars(part.data(), part.data() + part.size(), v);
    if (ec != std::errc() || end != part.data() + part.size() || part.empty()) return std::nullopt;
    return v;
  };
  const std::size_t slash = text.find('/');
  const auto num = readPart(text.substr(0, slash));
  const auto den = slash == std::string_view::npos ? std::optional<std::int64_t>(1)
                                                   : readPart(text.substr(slash + 1));
  if (!num || !den) return std::nullopt;
  return FrameRate{*num, *den};
}

void readFps(Context& cx, TableReader& r, OutputSettings& out) {
  const toml::node* node = r.take("fps");
  if (node == nullptr) return;
  const std::string path = r.pathOf("fps");
  const std::string expected =
      "frames per second, an integer from 1 to 1000000 or a ratio string like \"30000/1001\"";
  std::optional<FrameRate> rate;
  std::string shown;
  if (const auto s = node->value_exact<std::string>()) {
    rate = parseRatio(*s);
    shown = quote(*s);
    if (!rate) {
      cx.error(cx.at(*node), path, shown + " is not a frame rate (expected " + expected + ")");
      return;
    }
  } else if (const auto i = node->value_exact<std::int64_t>()) {
    rate = FrameRate{*i, 1};
    shown = std::to_string(*i);
  } else {
    cx.error(cx.at(*node), path, describe(*node) + " (expected " + expected + ")");
    return;
  }
  if (rate->numerator < 1 || rate->numerator > kMaxFrameRatePart || rate->denominator < 1 ||
      rate->denominator > kMaxFrameRatePart) {
    cx.error(cx.at(*node), path, shown + " is out of range (expected " + expected + ")");
    return;
  }
  try {
    frameDuration(*rate);
  } catch (const std::invalid_argument&) {
    cx.error(cx.at(*node), path,
             shown +
                 " frames per second do not last a whole number of flicks (expected a rate "
                 "whose frame is a whole number of 1/705600000 s, such as 24, 25, 30, 60, 120 "
                 "or \"30000/1001\")");
    return;
  }
  cx.record(path, *node);
  out.fps = *rate;
}

void readOutput(Context& cx, const toml::table& table, OutputSettings& out) {
  TableReader r(cx, table, "output");
  readFps(cx, r, out);
  const bool hasSeconds = r.number("seconds", out.seconds, "seconds, a number > 0 and <= 1e9",
                                   Range{0.0, kMaxRunSeconds, true});
  std::int64_t frames = 0;
  if (r.integer("frames", frames, "an integer from 1 to 1000000000", 1, kMaxRunFrames)) {
    if (hasSeconds || table.get("seconds") != nullptr) {
      cx.error(cx.at(*table.get("frames")), r.pathOf("frames"),
               "given together with output.seconds (expected either seconds or frames)");
    } else {
      out.frames = frames;
    }
  }
  if (const toml::node* node = r.take("formats")) {
    const std::string path = r.pathOf("formats");
    if (const toml::array* array = node->as_array()) {
      std::vector<CacheFormat> formats;
      bool ok = true;
      for (std::size_t i = 0; i < array->size(); ++i) {
        const std::string entryPath = childPath(path, i);
        const auto name = checkChoice(cx, *array->get(i), entryPath, kCacheFormats, "cache format");
        if (!name) {
          ok = false;
          continue;
        }
        const CacheFormat f = *cacheFormatFromName(*name);  // checkChoice took a known name
        if (std::find(formats.begin(), formats.end(), f) != formats.end()) {
          cx.error(cx.at(*array->get(i)), entryPath,
                   quote(*name) + " is listed twice (expected each format at most once)");
          ok = false;
          continue;
        }
        formats.push_back(f);
      }
      if (ok) {
        cx.record(path, *node);
        out.formats = formats;
      }
    } else {
      cx.error(
          cx.at(*node), path,
          describe(*node) + " (expected an array of cache formats, such as [\"csv\", \"ply\"])");
    }
  }
  r.string("directory", out.directory, "a directory path, a non-empty string");
  std::string name;
  if (r.choice("vdb_compression", name, vdbCompressionNames(), "VDB compression"))
    out.vdb.compression = *vdbCompressionNamed(name);
  if (r.choice("vdb_positions", name, vdbPositionsNames(), "VDB positions"))
    out.vdb.positions = *vdbPositionsNamed(name);
  r.finish();
}

// An array of tables ([[emitters]], [[forces]]): each entry handed to `read`.
template <typename Read>
void readEntries(Context& cx, TableReader& top, std::string_view key, bool required, Read read) {
  const toml::node* node = top.take(key);
  const std::string path(key);
  const std::string expected = "an array of tables, written [[" + path + "]]";
  if (node == nullptr) {
    if (required) top.missing(key, "at least one [[" + path + "]] table");
    return;
  }
  const toml::array* array = node->as_array();
  if (array == nullptr) {
    cx.error(cx.at(*node), path, describe(*node) + " (expected " + expected + ")");
    return;
  }
  if (array->empty() && required) {
    cx.error(cx.at(*node), path,
             "got an empty array (expected at least one [[" + path + "]] table)");
    return;
  }
  if (array->size() > kMaxEntries) {
    cx.error(cx.at(*node), path,
             std::to_string(array->size()) + " entries are too many (expected at most 10000)");
    return;
  }
  cx.record(path, *node);
  for (std::size_t i = 0; i < array->size(); ++i) {
    const toml::node& entry = *array->get(i);
    if (const toml::table* table = entry.as_table()) {
      read(*table, i);
    } else {
      cx.error(cx.at(entry), childPath(path, i), describe(entry) + " (expected a table)");
    }
  }
}

// Validates a document of the current version (format_version was handled by the migration).
EffectSettings readCurrentVersion(Context& cx, const toml::table& document) {
  EffectSettings effect;
  TableReader top(cx, document, "");
  if (const toml::node* version = top.take("format_version");
      version && cx.origins().labelOf(*version)) {
    cx.error(cx.at(*version), "format_version",
             "cannot be changed by an override (expected the version the file is written in)");
  }

  if (const toml::node* node = top.take("simulation")) {
    if (const toml::table* table = node->as_table()) {
      readSimulation(cx, *table, effect.simulation);
    } else {
      cx.error(cx.at(*node), "simulation", describe(*node) + " (expected a [simulation] table)");
    }
  } else {
    top.missing("simulation", "a [simulation] table with at least step_rate");
  }

  const auto maxParticles = static_cast<std::int64_t>(effect.simulation.maxParticles);
  std::map<std::string, std::size_t> names;
  readEntries(cx, top, "emitters", /*required=*/true, [&](const toml::table& table, std::size_t i) {
    readEmitterEntry(cx, table, i, maxParticles, effect, names);
  });
  std::vector<std::size_t> forceEntries;
  readEntries(cx, top, "forces", /*required=*/false, [&](const toml::table& table, std::size_t i) {
    const std::size_t errorsBefore = cx.diagnostics().size();
    if (auto force = readForce(cx, table, i)) {
      if (cx.diagnostics().size() == errorsBefore) {
        reportProblems(cx, childPath("forces", i), forceProblems(*force));
      }
      effect.forces.push_back(*force);
      forceEntries.push_back(i);
    }
  });
  checkAdvection(cx, effect, forceEntries);

  if (const toml::node* node = top.take("output")) {
    if (const toml::table* table = node->as_table()) {
      readOutput(cx, *table, effect.output);
    } else {
      cx.error(cx.at(*node), "output", describe(*node) + " (expected an [output] table)");
    }
  }
  top.finish();
  return effect;
}

// Turns a document of version `from` into version from + 1 in place. Each change of the format
// adds a case (renamed keys, new required keys given the values that keep the old behaviour), so
// files of every earlier version keep loading.
void migrateOneVersion(toml::table& /*document*/, std::int64_t from) {
  switch (from) {
    default:
      throw std::logic_error("no migration from format_version " + std::to_string(from));
  }
}

// Reads format_version and brings an older document up to the current version. Returns false
// when the document is of a version this build cannot read (nothing else is worth reporting).
bool migrateToCurrent(Context& cx, toml::table& document) {
  const std::string expected = "format_version = " + std::to_string(kEffectFormatVersion);
  const toml::node* node = document.get("format_version");
  if (node == nullptr) {
    cx.error(cx.at(document), "format_version", "missing (expected " + expected + ")");
    return true;  // read it as the current version, to report everything else too
  }
  const auto version = node->value_exact<std::int64_t>();
  if (!version) {
    cx.error(cx.at(*node), "format_version", describe(*node) + " (expected " + expected + ")");
    return true;
  }
  if (*version < 1 || *version > kEffectFormatVersion) {
    const std::string known = kEffectFormatVersion == 1
                                  ? std::string("1")
                                  : "1 to " + std::to_string(kEffectFormatVersion);
    cx.error(cx.at(*node), "format_version",
             "version " + std::to_string(*version) + " is not one this build reads (expected " +
                 known + ")");
    return false;
  }
  cx.record("format_version", *node);
  for (std::int64_t from = *version; from < kEffectFormatVersion; ++from)
    migrateOneVersion(document, from);
  return true;
}

}  // namespace
}  // namespace detail

LoadResult parseEffect(std::string_view text, std::string_view fileName,
                       const std::vector<std::string>& overrides) {
  LoadResult result;
  result.fingerprint = effectFingerprint(text, overrides);
  const std::string file(fileName);
  toml::table document;
  try {
    document = toml::parse(text, std::string_view(file));
  } catch (const toml::parse_error& e) {
    const toml::source_position& begin = e.source().begin;
    result.diagnostics.push_back(Diagnostic{Severity::Error, file, static_cast<int>(begin.line),
                                            static_cast<int>(begin.column), "",
                                            std::string(e.description())});
    return result;
  }

  OverrideOrigins origins;
  detail::Context cx(file, origins);
  if (detail::migrateToCurrent(cx, document)) {
    const std::vector<Diagnostic> overrideErrors = applyOverrides(document, overrides, origins);
    cx.diagnostics().insert(cx.diagnostics().end(), overrideErrors.begin(), overrideErrors.end());
    EffectSettings effect = detail::readCurrentVersion(cx, document);
    if (!hasErrors(cx.diagnostics())) {
      effect.sources = std::move(cx.sources());
      result.effect = std::move(effect);
    }
  }
  result.diagnostics = std::move(cx.diagnostics());
  // Findings about overrides in command-line order, then the file's by position.
  std::map<std::string, std::size_t> rank;
  for (std::size_t i = 0; i < overrides.size(); ++i) rank.emplace(overrideLabel(overrides[i]), i);
  std::stable_sort(result.diagnostics.begin(), result.diagnostics.end(),
                   [&](const Diagnostic& a, const Diagnostic& b) {
                     const auto ra = rank.find(a.file), rb = rank.find(b.file);
                     return (ra == rank.end() ? overrides.size() : ra->second) <
                            (rb == rank.end() ? overrides.size() : rb->second);
                   });
  sortDiagnostics(result.diagnostics);
  return result;
}

LoadResult loadEffectFile(const std::filesystem::path& path,
                          const std::vector<std::string>& overrides) {
  const std::string file = path.string();
  std::error_code ec;
  std::string problem;
  if (!std::filesystem::exists(path, ec)) {
    problem = "no such file";
  } else if (std::filesystem::is_directory(path, ec)) {
    problem = "is a directory";
  }
  std::ifstream in;
  if (problem.empty()) {
    in.open(path, std::ios::binary);
    if (!in) problem = "cannot be opened";
  }
  if (!problem.empty()) {
    LoadResult result;
    result.diagnostics.push_back(Diagnostic{Severity::Error, file, 0, 0, "",
                                            problem + " (expected a readable effect file)"});
    return result;
  }
  std::ostringstream text;
  text << in.rdbuf();
  return parseEffect(text.str(), file, overrides);
}

}  // namespace tickfx::io
