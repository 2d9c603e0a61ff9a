#include "io/effect/SettingOverrides.h"

#include <charconv>
#include <optional>
#include <string_view>

namespace tickfx::io {
namespace {

std::string_view trim(std::string_view s) {
  const auto space = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; };
  while (!s.empty() && space(s.front())) s.remove_prefix(1);
  while (!s.empty() && space(s.back())) s.remove_suffix(1);
  return s;
}

bool isKeyChar(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
         c == '-';
}

std::optional<std::vector<std::string>> splitPath(std::string_view path) {
  std::vector<std::string> segments;
  std::size_t begin = 0;
  while (true) {
    const std::size_t dot = path.find('.', begin);
    const std::string_view segment =
        path.substr(begin, dot == std::string_view::npos ? std::string_view::npos : dot - begin);
    if (segment.empty()) return std::nullopt;
    for (char c : segment) {
      if (!isKeyChar(c)) return std::nullopt;
    }
    segments.emplace_back(segment);
    if (dot == std::string_view::npos) return segments;
    begin = dot + 1;
  }
}

std::optional<std::size_t> entryNumber(std::string_view segment) {
  std::size_t n = 0;
  const auto [end, ec] = std::from_chars(segment.data(), segment.data() + segment.size(), n);
  if (ec != std::errc() || end != segment.data() + segment.size()) return std::nullopt;
  return n;
}

// A word the shell would pass unquoted and TOML would not read: taken as a string.
bool isPlainWord(std::string_view s) {
  for (char c : s) {
    if (c == ' ' || c == '\t' || c == '"' || c == '\'' || c == '[' || c == ']' || c == '{' ||
        c == '}' || c == ',' || c == '=' || c == '#' || c == '\n' || c == '\r') {
      return false;
    }
  }
  return !s.empty();
}

// The value as a one-entry table {v = value}, or nothing when it is not a value.
std::optional<toml::table> readValue(std::string_view text) {
  if (text.find_first_of("\r\n") == std::string_view::npos) {
    try {
      toml::table parsed = toml::parse("v = " + std::string(text));
      if (parsed.size() == 1 && parsed.contains("v")) return parsed;
    } catch (const toml::parse_error&) {
      // Not TOML: maybe a plain word.
    }
  }
  if (!isPlainWord(text)) return std::nullopt;
  toml::table wrapped;
  wrapped.insert("v", std::string(text));
  return wrapped;
}

std::string typeWord(const toml::node& node) {
  switch (node.type()) {
    case toml::node_type::string:
      return "a string";
    case toml::node_type::integer:
      return "an integer";
    case toml::node_type::floating_point:
      return "a number";
    case toml::node_type::boolean:
      return "a boolean";
    default:
      return "a date or time";
  }
}

std::string joinPath(const std::vector<std::string>& segments, std::size_t count) {
  std::string out;
  for (std::size_t i = 0; i < count; ++i) {
    if (i > 0) out += '.';
    out += segments[i];
  }
  return out;
}

class Applier {
 public:
  Applier(toml::table& root, OverrideOrigins& origins, std::vector<Diagnostic>& out)
      : root_(root), origins_(origins), out_(out) {}

  void apply(std::string_view text);

 private:
  void fail(const std::string& file, const std::string& keyPath, std::string message) {
    out_.push_back(Diagnostic{Severity::Error, file, 0, 0, keyPath, std::move(message)});
  }
  static std::string entries(const std::string& arrayPath, std::size_t size) {
    if (size == 0) return arrayPath + " has no entries";
    return arrayPath + " has " + std::to_string(size) + (size == 1 ? " entry" : " entries");
  }
  static std::string entryRange(std::size_t size) {
    if (size == 0) return "an existing entry";
    if (size == 1) return "entry number 0";
    return "an entry number from 0 to " + std::to_string(size - 1);
  }

  toml::table& root_;
  OverrideOrigins& origins_;
  std::vector<Diagnostic>& out_;
};

void Applier::apply(std::string_view rawText) {
  const std::string_view text = trim(rawText);
  const std::string label = overrideLabel(text);
  const std::size_t eq = text.find('=');
  if (eq == std::string_view::npos) {
    fail(label, "", "malformed override (expected key.path=value, e.g. simulation.step_rate=120)");
    return;
  }
  const std::string_view pathText = trim(text.substr(0, eq));
  const std::string_view valueText = trim(text.substr(eq + 1));
  const std::optional<std::vector<std::string>> path = splitPath(pathText);
  if (!path) {
    fail(label, "",
         "malformed key path \"" + std::string(pathText) +
             "\" (expected keys and entry numbers joined by dots, e.g. forces.1.frequency)");
    return;
  }
  const std::string keyPath(pathText);
  if (valueText.empty()) {
    fail(label, keyPath, "missing value (expected key.path=value)");
    return;
  }
  std::optional<toml::table> wrapped = readValue(valueText);
  if (!wrapped) {
    fail(label, keyPath,
         "cannot read \"" + std::string(valueText) +
             "\" as a value (expected a TOML value: a number, true or false, a word or a quoted "
             "string, an array like [1, 2, 3])");
    return;
  }
  toml::node& value = *wrapped->get("v");

  // Walk to the container of the last segment, creating missing tables on the way.
  toml::node* container = &root_;
  const std::vector<std::string>& segments = *path;
  for (std::size_t i = 0; i + 1 < segments.size(); ++i) {
    const std::string here = joinPath(segments, i + 1);
    toml::node* next = nullptr;
    if (toml::table* table = container->as_table()) {
      next = table->get(segments[i]);
      if (next == nullptr) {
        if (entryNumber(segments[i + 1])) {
          fail(label, here,
               "no such array (expected entries written in the file: --set changes them, it "
               "does not add them)");
          return;
        }
        next = table->insert(segments[i], toml::table{}).first->second.as_table();
        origins_.mark(*next, label);
      }
    } else if (toml::array* array = container->as_array()) {
      const std::optional<std::size_t> n = entryNumber(segments[i]);
      const std::string arrayPath = joinPath(segments, i);
      if (!n || *n >= array->size()) {
        fail(label, here,
             (n ? "no such entry: " + entries(arrayPath, array->size())
                : arrayPath + " is an array") +
                 " (expected " + entryRange(array->size()) + ")");
        return;
      }
      next = array->get(*n);
    }
    if (!next->is_table() && !next->is_array()) {
      fail(label, here,
           "is " + typeWord(*next) + ", not a table (expected a path through tables and arrays)");
      return;
    }
    container = next;
  }

  const std::string& last = segments.back();
  if (toml::table* table = container->as_table()) {
    if (const toml::node* old = table->get(last)) origins_.unmark(*old);
    table->insert_or_assign(last, std::move(value));
    origins_.mark(*table->get(last), label);
  } else if (toml::array* array = container->as_array()) {
    const std::optional<std::size_t> n = entryNumber(last);
    const std::string arrayPath = joinPath(segments, segments.size() - 1);
    if (!n || *n >= array->size()) {
      fail(
          label, keyPath,
          (n ? "no such entry: " + entries(arrayPath, array->size()) : arrayPath + " is an array") +
              " (expected " + entryRange(array->size()) + ")");
      return;
    }
    origins_.unmark(*array->get(*n));
    array->replace(array->cbegin() + static_cast<std::ptrdiff_t>(*n), std::move(value));
    origins_.mark(*array->get(*n), label);
  }
}

}  // namespace

std::string overrideLabel(std::string_view overrideText) {
  const std::string_view text = trim(overrideText);
  const std::size_t eq = text.find('=');
  if (eq != std::string_view::npos) {
    const std::string_view pathText = trim(text.substr(0, eq));
    if (splitPath(pathText)) return "--set " + std::string(pathText);
  }
  return "--set " + std::string(text);
}

const std::string* OverrideOrigins::labelOf(const toml::node& node) const {
  const auto it = labels_.find(&node);
  return it == labels_.end() ? nullptr : &it->second;
}

void OverrideOrigins::mark(const toml::node& node, const std::string& label) {
  labels_.insert_or_assign(&node, label);
  if (const toml::table* table = node.as_table()) {
    for (const auto& [key, child] : *table) mark(child, label);
  } else if (const toml::array* array = node.as_array()) {
    for (const toml::node& child : *array) mark(child, label);
  }
}

void OverrideOrigins::unmark(const toml::node& node) {
  labels_.erase(&node);
  if (const toml::table* table = node.as_table()) {
    for (const auto& [key, child] : *table) unmark(child);
  } else if (const toml::array* array = node.as_array()) {
    for (const toml::node& child : *array) unmark(child);
  }
}

std::vector<Diagnostic> applyOverrides(toml::table& root, const std::vector<std::string>& overrides,
                                       OverrideOrigins& origins) {
  std::vector<Diagnostic> diagnostics;
  Applier applier(root, origins, diagnostics);
  for (const std::string& text : overrides) applier.apply(text);
  return diagnostics;
}

}  // namespace tickfx::io
