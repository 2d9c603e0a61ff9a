#include "io/effect/EffectMigration.h"

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>

#include "io/effect/EffectSettings.h"

namespace tickfx::io::detail {
namespace {

// Turns a document of version `from` into version from + 1 in place. Each change of the format
// adds a case (renamed keys, new required keys given the values that keep the old behaviour), so
// files of every earlier version keep loading.
void migrateOneVersion(toml::table& /*document*/, std::int64_t from) {
  switch (from) {
    default:
      throw std::logic_error("no migration from format_version " + std::to_string(from));
  }
}

}  // namespace

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

}  // namespace tickfx::io::detail
