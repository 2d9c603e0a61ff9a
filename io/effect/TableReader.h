// Internal to the effect parser (not installed): reading the values and tables of one effect
// document. Every check reports what is wrong as an error Diagnostic,
//   FILE:LINE:COL: error: key.path: what is wrong (what is expected)
// at the offending value (at the key for an unknown key, at the table's header for a missing
// one), and records where each value it accepts was written (Context::sources()).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include <toml++/toml.h>

#include "io/effect/Diagnostics.h"
#include "io/effect/SettingOverrides.h"
#include "io/effect/SourceMap.h"
#include "particles/SettingProblem.h"

namespace tickfx::io::detail {

// The bound on every unbounded quantity (positions, speeds, accelerations, times): far beyond any
// effect, and far inside the float range the simulation rounds to.
inline constexpr double kBig = 1e9;

// "(expected …)" texts that several sections share.
inline constexpr char kPositionText[] = "[x, y, z] in metres, each from -1e9 to 1e9";
inline constexpr char kDirectionText[] =
    "a direction [x, y, z], each from -1e9 to 1e9, not all zero";
inline constexpr char kSecondsText[] = "seconds, a number from 0 to 1e9";

// A closed or half-open interval; messages spell the bounds out in the "expected" text.
struct Range {
  double min = -kBig;
  double max = kBig;
  bool minOpen = false;
  bool maxOpen = false;

  bool contains(double v) const {
    return (minOpen ? v > min : v >= min) && (maxOpen ? v < max : v <= max);
  }
};

// Where findings go while one document is read: the diagnostics, in the order reported, and the
// source map of the values accepted.
class Context {
 public:
  Context(std::string file, const OverrideOrigins& origins)
      : file_(std::move(file)), origins_(origins) {}

  // Where `node` is written, or its override's label (line 0) when an override set it.
  SourceLocation at(const toml::node& node) const;
  // Where the key `key` (of `value`) is written: an unknown key is shown at its name.
  SourceLocation atKey(const toml::key& key, const toml::node& value) const;

  void error(const SourceLocation& where, std::string keyPath, std::string message);
  // Records that `keyPath` was written at `node`.
  void record(std::string keyPath, const toml::node& node);

  const std::string& file() const { return file_; }
  const OverrideOrigins& origins() const { return origins_; }
  // The effect file's directory: files an effect names are relative to it.
  std::filesystem::path directory() const { return std::filesystem::path(file_).parent_path(); }
  std::vector<Diagnostic>& diagnostics() { return diagnostics_; }
  SourceMap& sources() { return sources_; }

 private:
  std::string file_;
  const OverrideOrigins& origins_;
  std::vector<Diagnostic> diagnostics_;
  SourceMap sources_;
};

// What the core type that owns an entry's settings refuses in them (its validate()), shown where
// each key was written, or at the entry's header for a default. Only for an entry read without
// errors: every value is then the file's or a documented default, never a default standing in
// for a value already refused, and no condition the reader words itself is reported twice.
void reportProblems(Context& cx, const std::string& entryPath, const SettingProblems& problems);

// "parent.key" ("key" when `parent` is empty) and "parent.index".
std::string childPath(std::string_view parent, std::string_view key);
std::string childPath(std::string_view parent, std::size_t index);
// "a, b, c".
std::string joinWords(const std::vector<std::string>& words);
// `s` in double quotes, cut to 40 characters and "...".
std::string quote(std::string_view s);
// A float as written in TOML: with a fraction, so that 60.0 does not read as the integer 60.
std::string floatText(double v);
// What a value is, for "got …" messages ("got a string \"x\"", "got an array").
std::string describe(const toml::node& node);

// ---- single values
// Each check reports what is wrong with `node` (at `path`) and returns nothing, or records where
// it is written and returns the value. `expected` is the "(expected …)" text: the unit and the
// range.

// An integer or a float, finite and in `range`.
std::optional<double> checkNumber(Context& cx, const toml::node& node, const std::string& path,
                                  const std::string& expected, const Range& range);
// An integer (not a float) from `min` to `max`.
std::optional<std::int64_t> checkInteger(Context& cx, const toml::node& node,
                                         const std::string& path, const std::string& expected,
                                         std::int64_t min, std::int64_t max);
// One of `names`, with a suggestion when the word is close to one.
std::optional<std::string> checkChoice(Context& cx, const toml::node& node, const std::string& path,
                                       const std::vector<std::string>& names,
                                       std::string_view what);

// ---- tables

// Reads the keys of one table. Every key a reader asks for is known; finish() reports the rest.
// Each read reports what is wrong with the key's value and returns false, leaving `out` as it
// was; an absent key returns false without a report unless it is required.
class TableReader {
 public:
  // Records the table at `path`, its header.
  TableReader(Context& cx, const toml::table& table, std::string path);

  const std::string& path() const { return path_; }
  std::string pathOf(std::string_view key) const { return childPath(path_, key); }
  const toml::table& table() const { return table_; }

  // The value of `key`, or nullptr; the key becomes known either way.
  const toml::node* take(std::string_view key);

  // A required key is missing: the error points at the table's header.
  void missing(std::string_view key, const std::string& expected);

  template <typename T>
  bool number(std::string_view key, T& out, const std::string& expected, const Range& range,
              bool required = false) {
    const toml::node* node = take(key);
    if (node == nullptr) {
      if (required) missing(key, expected);
      return false;
    }
    const std::optional<double> v = checkNumber(cx_, *node, pathOf(key), expected, range);
    if (v) out = static_cast<T>(*v);
    return v.has_value();
  }

  template <typename T>
  bool integer(std::string_view key, T& out, const std::string& expected, std::int64_t min,
               std::int64_t max, bool required = false) {
    const toml::node* node = take(key);
    if (node == nullptr) {
      if (required) missing(key, expected);
      return false;
    }
    const std::optional<std::int64_t> v = checkInteger(cx_, *node, pathOf(key), expected, min, max);
    if (v) out = static_cast<T>(*v);
    return v.has_value();
  }

  bool boolean(std::string_view key, bool& out);

  // A non-empty string.
  bool string(std::string_view key, std::string& out, const std::string& expected);

  bool choice(std::string_view key, std::string& out, const std::vector<std::string>& names,
              std::string_view what, bool required = false);

  // [x, y, z], each component in `range`; `nonZero` for directions.
  bool vec3(std::string_view key, Eigen::Vector3d& out, const std::string& expected,
            const Range& range, bool nonZero = false);

  // Marks keys as known without reading them (parameters of a variant that could not be told).
  void allow(const std::vector<std::string>& keys);

  // Reports every key nobody asked for. `notHere` holds keys that belong to another variant
  // (another shape, another force type) and why they do not apply to this one.
  void finish(const std::map<std::string, std::string>& notHere = {});

 private:
  Context& cx_;
  const toml::table& table_;
  std::string path_;
  std::set<std::string> known_;
  std::vector<std::string> knownOrder_;
};

}  // namespace tickfx::io::detail
