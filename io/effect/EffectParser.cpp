#include "io/effect/EffectParser.h"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <utility>

#include <toml++/toml.h>

#include "io/effect/EffectBuilder.h"
#include "io/effect/EffectMigration.h"
#include "io/effect/ParseColliders.h"
#include "io/effect/ParseEmitters.h"
#include "io/effect/ParseForces.h"
#include "io/effect/ParseOutput.h"
#include "io/effect/ParseSimulation.h"
#include "io/effect/ParseSubEmitters.h"
#include "io/effect/ParseVectorFields.h"
#include "io/effect/SettingOverrides.h"
#include "io/effect/TableReader.h"
#include "io/util/Fingerprint.h"

#if !TOML_EXCEPTIONS
#error "tickfx_io reads parse errors from toml::parse_error: build toml++ with exceptions"
#endif

namespace tickfx::io {
namespace detail {
namespace {

constexpr std::size_t kMaxEntries = 10'000;  // emitters, forces, colliders

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
  readEntries(cx, top, "colliders", /*required=*/false,
              [&](const toml::table& table, std::size_t i) {
                if (auto collider = readCollider(cx, table, i)) {
                  effect.colliders.push_back(*collider);
                }
              });

  if (const toml::node* node = top.take("output")) {
    if (const toml::table* table = node->as_table()) {
      readOutput(cx, *table, effect.output);
    } else {
      cx.error(cx.at(*node), "output", describe(*node) + " (expected an [output] table)");
    }
  }
  checkSubEmitters(cx, effect);
  top.finish();
  return effect;
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
