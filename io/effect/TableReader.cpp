#include "io/effect/TableReader.h"

#include <cmath>
#include <utility>

#include "io/effect/EditDistance.h"

namespace tickfx::io::detail {

SourceLocation Context::at(const toml::node& node) const {
  if (const std::string* label = origins_.labelOf(node)) return {*label, 0, 0};
  const toml::source_position& begin = node.source().begin;
  return {file_, static_cast<int>(begin.line), static_cast<int>(begin.column)};
}

SourceLocation Context::atKey(const toml::key& key, const toml::node& value) const {
  if (const std::string* label = origins_.labelOf(value)) return {*label, 0, 0};
  const toml::source_position& begin = key.source().begin;
  if (begin.line == 0) return at(value);
  return {file_, static_cast<int>(begin.line), static_cast<int>(begin.column)};
}

void Context::error(const SourceLocation& where, std::string keyPath, std::string message) {
  diagnostics_.push_back(Diagnostic{Severity::Error, where.file, where.line, where.column,
                                    std::move(keyPath), std::move(message)});
}

void Context::record(std::string keyPath, const toml::node& node) {
  sources_.set(std::move(keyPath), at(node));
}

void reportProblems(Context& cx, const std::string& entryPath, const SettingProblems& problems) {
  for (const SettingProblem& p : problems) {
    const std::string path = entryPath + "." + p.key;
    cx.error(cx.sources().find(path), path, p.message + " (expected " + p.expected + ")");
  }
}

std::string childPath(std::string_view parent, std::string_view key) {
  return parent.empty() ? std::string(key) : std::string(parent) + "." + std::string(key);
}

std::string childPath(std::string_view parent, std::size_t index) {
  return childPath(parent, std::to_string(index));
}

std::string joinWords(const std::vector<std::string>& words) {
  std::string out;
  for (const std::string& w : words) out += (out.empty() ? "" : ", ") + w;
  return out;
}

std::string quote(std::string_view s) {
  constexpr std::size_t kLimit = 40;
  if (s.size() > kLimit) return "\"" + std::string(s.substr(0, kLimit)) + "...\"";
  return "\"" + std::string(s) + "\"";
}

std::string floatText(double v) {
  std::string s = formatNumber(v);
  if (s.find_first_of(".eni") == std::string::npos) s += ".0";
  return s;
}

std::string describe(const toml::node& node) {
  switch (node.type()) {
    case toml::node_type::string:
      return "got a string " + quote(*node.value<std::string_view>());
    case toml::node_type::integer:
      return "got the integer " + std::to_string(*node.value<std::int64_t>());
    case toml::node_type::floating_point:
      return "got the number " + floatText(*node.value<double>());
    case toml::node_type::boolean:
      return std::string("got ") + (*node.value<bool>() ? "true" : "false");
    case toml::node_type::array:
      return "got an array";
    case toml::node_type::table:
      return "got a table";
    default:
      return "got a date or time";
  }
}

// ---- single values ------------------------------------------------------------------------------

std::optional<double> checkNumber(Context& cx, const toml::node& node, const std::string& path,
                                  const std::string& expected, const Range& range) {
  std::optional<double> v;
  if (const auto i = node.value_exact<std::int64_t>()) v = static_cast<double>(*i);
  if (const auto f = node.value_exact<double>()) v = *f;
  if (!v) {
    cx.error(cx.at(node), path, describe(node) + " (expected " + expected + ")");
    return std::nullopt;
  }
  if (!std::isfinite(*v)) {
    cx.error(cx.at(node), path,
             formatNumber(*v) + " is not a finite number (expected " + expected + ")");
    return std::nullopt;
  }
  if (!range.contains(*v)) {
    cx.error(cx.at(node), path, formatNumber(*v) + " is out of range (expected " + expected + ")");
    return std::nullopt;
  }
  cx.record(path, node);
  return v;
}

std::optional<std::int64_t> checkInteger(Context& cx, const toml::node& node,
                                         const std::string& path, const std::string& expected,
                                         std::int64_t min, std::int64_t max) {
  if (const auto f = node.value_exact<double>()) {
    cx.error(cx.at(node), path, floatText(*f) + " is not an integer (expected " + expected + ")");
    return std::nullopt;
  }
  const auto v = node.value_exact<std::int64_t>();
  if (!v) {
    cx.error(cx.at(node), path, describe(node) + " (expected " + expected + ")");
    return std::nullopt;
  }
  if (*v < min || *v > max) {
    cx.error(cx.at(node), path,
             std::to_string(*v) + " is out of range (expected " + expected + ")");
    return std::nullopt;
  }
  cx.record(path, node);
  return v;
}

std::optional<std::string> checkChoice(Context& cx, const toml::node& node, const std::string& path,
                                       const std::vector<std::string>& names,
                                       std::string_view what) {
  const auto v = node.value_exact<std::string>();
  if (!v) {
    cx.error(
        cx.at(node), path,
        describe(node) + " (expected " + std::string(what) + ", one of: " + joinWords(names) + ")");
    return std::nullopt;
  }
  for (const std::string& name : names) {
    if (*v == name) {
      cx.record(path, node);
      return v;
    }
  }
  const std::optional<std::string> guess = closestMatch(*v, names);
  cx.error(cx.at(node), path,
           "unknown " + std::string(what) + " " + quote(*v) +
               (guess ? " (did you mean " + quote(*guess) + "?)"
                      : " (expected one of: " + joinWords(names) + ")"));
  return std::nullopt;
}

// ---- tables -------------------------------------------------------------------------------------

TableReader::TableReader(Context& cx, const toml::table& table, std::string path)
    : cx_(cx), table_(table), path_(std::move(path)) {
  cx_.record(path_, table_);
}

const toml::node* TableReader::take(std::string_view key) {
  if (known_.insert(std::string(key)).second) knownOrder_.emplace_back(key);
  return table_.get(key);
}

void TableReader::missing(std::string_view key, const std::string& expected) {
  cx_.error(cx_.at(table_), pathOf(key), "missing (expected " + expected + ")");
}

bool TableReader::boolean(std::string_view key, bool& out) {
  const toml::node* node = take(key);
  if (node == nullptr) return false;
  const auto v = node->value_exact<bool>();
  if (!v) {
    cx_.error(cx_.at(*node), pathOf(key), describe(*node) + " (expected true or false)");
    return false;
  }
  cx_.record(pathOf(key), *node);
  out = *v;
  return true;
}

bool TableReader::string(std::string_view key, std::string& out, const std::string& expected) {
  const toml::node* node = take(key);
  if (node == nullptr) return false;
  const auto v = node->value_exact<std::string>();
  if (!v || v->empty()) {
    cx_.error(cx_.at(*node), pathOf(key),
              (v ? std::string("got an empty string") : describe(*node)) + " (expected " +
                  expected + ")");
    return false;
  }
  cx_.record(pathOf(key), *node);
  out = *v;
  return true;
}

bool TableReader::choice(std::string_view key, std::string& out,
                         const std::vector<std::string>& names, std::string_view what,
                         bool required) {
  const toml::node* node = take(key);
  if (node == nullptr) {
    if (required) missing(key, std::string(what) + ", one of: " + joinWords(names));
    return false;
  }
  const std::optional<std::string> v = checkChoice(cx_, *node, pathOf(key), names, what);
  if (v) out = *v;
  return v.has_value();
}

bool TableReader::vec3(std::string_view key, Eigen::Vector3d& out, const std::string& expected,
                       const Range& range, bool nonZero) {
  const toml::node* node = take(key);
  if (node == nullptr) return false;
  const std::string path = pathOf(key);
  const toml::array* array = node->as_array();
  if (array == nullptr) {
    cx_.error(cx_.at(*node), path, describe(*node) + " (expected " + expected + ")");
    return false;
  }
  if (array->size() != 3) {
    cx_.error(cx_.at(*node), path,
              "got " + std::to_string(array->size()) +
                  (array->size() == 1 ? " entry" : " entries") + " (expected " + expected + ")");
    return false;
  }
  Eigen::Vector3d v;
  bool ok = true;
  for (std::size_t i = 0; i < 3; ++i) {
    const std::optional<double> c =
        checkNumber(cx_, *array->get(i), childPath(path, i), expected, range);
    if (c) v[static_cast<Eigen::Index>(i)] = *c;
    ok = ok && c.has_value();
  }
  if (!ok) return false;
  if (nonZero && v.isZero(0.0)) {
    cx_.error(cx_.at(*node), path, "got [0, 0, 0] (expected " + expected + ")");
    return false;
  }
  cx_.record(path, *node);
  out = v;
  return true;
}

void TableReader::allow(const std::vector<std::string>& keys) {
  for (const std::string& k : keys) take(k);
}

void TableReader::finish(const std::map<std::string, std::string>& notHere) {
  for (const auto& [key, value] : table_) {
    const std::string name(key.str());
    if (known_.count(name) != 0) continue;
    const std::string path = pathOf(name);
    if (const auto it = notHere.find(name); it != notHere.end()) {
      cx_.error(cx_.atKey(key, value), path, it->second);
      continue;
    }
    const std::optional<std::string> guess = closestMatch(name, knownOrder_);
    cx_.error(cx_.atKey(key, value), path,
              "unknown key " + quote(name) +
                  (guess ? " (did you mean " + quote(*guess) + "?)"
                         : " (expected one of: " + joinWords(knownOrder_) + ")"));
  }
}

}  // namespace tickfx::io::detail
