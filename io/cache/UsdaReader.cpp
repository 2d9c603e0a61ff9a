#include "io/cache/UsdaReader.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>

#include "io/cache/AttributeGroups.h"

namespace tickfx::io {
namespace {

// ---- tokens ------------------------------------------------------------------------------------

enum class Tok { End, Punct, Word, Number, String, Path };

struct Token {
  Tok kind = Tok::End;
  std::string_view text;
  std::size_t offset = 0;
};

bool wordStart(char c) { return std::isalpha(static_cast<unsigned char>(c)) != 0 || c == '_'; }
bool wordChar(char c) { return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_'; }

// USD's text grammar cut into tokens: punctuation, words (namespaced with ':'), numbers (with
// inf and nan as words), strings ('', "" and their triple forms), paths <...>; '#' comments.
class Lexer {
 public:
  explicit Lexer(std::string_view text) : s_(text) {}

  Token next() {
    skipSpace();
    Token t;
    t.offset = i_;
    if (i_ >= s_.size()) return t;
    const char c = s_[i_];
    if (c == '"' || c == '\'') return string(c);
    if (c == '<') {
      const std::size_t end = s_.find('>', i_);
      if (end == std::string_view::npos) return t;  // cut short
      t = {Tok::Path, s_.substr(i_, end + 1 - i_), i_};
      i_ = end + 1;
      return t;
    }
    const bool sign = (c == '-' || c == '+') && i_ + 1 < s_.size();
    const char d = sign ? s_[i_ + 1] : c;
    if (std::isdigit(static_cast<unsigned char>(d)) != 0 ||
        (d == '.' && i_ + 1 + sign < s_.size() &&
         std::isdigit(static_cast<unsigned char>(s_[i_ + 1 + sign])) != 0)) {
      std::size_t j = i_ + (sign ? 1 : 0);
      while (j < s_.size() &&
             (std::isdigit(static_cast<unsigned char>(s_[j])) != 0 || s_[j] == '.' ||
              s_[j] == 'e' || s_[j] == 'E' ||
              ((s_[j] == '-' || s_[j] == '+') && (s_[j - 1] == 'e' || s_[j - 1] == 'E')))) {
        ++j;
      }
      t = {Tok::Number, s_.substr(i_, j - i_), i_};
      i_ = j;
      return t;
    }
    if (wordStart(d)) {
      std::size_t j = i_ + (sign ? 1 : 0);
      while (j < s_.size() &&
             (wordChar(s_[j]) || (s_[j] == ':' && j + 1 < s_.size() && wordStart(s_[j + 1])))) {
        ++j;
      }
      t = {Tok::Word, s_.substr(i_, j - i_), i_};
      i_ = j;
      return t;
    }
    t = {Tok::Punct, s_.substr(i_, 1), i_};
    ++i_;
    return t;
  }

  std::size_t offset() const { return i_; }

 private:
  void skipSpace() {
    while (i_ < s_.size()) {
      if (std::isspace(static_cast<unsigned char>(s_[i_])) != 0) {
        ++i_;
      } else if (s_[i_] == '#') {
        while (i_ < s_.size() && s_[i_] != '\n') ++i_;
      } else {
        break;
      }
    }
  }
  Token string(char quote) {
    Token t{Tok::String, {}, i_};
    const bool triple = s_.substr(i_, 3) == std::string(3, quote);
    std::size_t j = i_ + (triple ? 3 : 1);
    while (j < s_.size()) {
      if (s_[j] == '\\') {
        j += 2;
        continue;
      }
      if (triple ? s_.substr(j, 3) == std::string(3, quote) : s_[j] == quote) {
        const std::size_t end = j + (triple ? 3 : 1);
        t.text = s_.substr(i_, end - i_);
        i_ = end;
        return t;
      }
      if (!triple && s_[j] == '\n') break;
      ++j;
    }
    return Token{};  // unterminated: cut short
  }

  std::string_view s_;
  std::size_t i_ = 0;
};

// ---- values ------------------------------------------------------------------------------------

// The scalars of a value, flattened: an array of tuples of numbers is `width` numbers an element.
struct Flat {
  std::vector<std::string_view> scalars;
  int width = 0;         // 0: not yet known (an empty array)
  bool blocked = false;  // None
};

struct Failure {
  std::string what;
};

class Parser {
 public:
  explicit Parser(std::string_view text) : lex_(text), text_(text) { advance(); }

  const Token& peek() const { return tok_; }
  Token take() {
    Token t = tok_;
    advance();
    return t;
  }
  bool is(std::string_view punct) const { return tok_.kind == Tok::Punct && tok_.text == punct; }
  bool isWord(std::string_view w) const { return tok_.kind == Tok::Word && tok_.text == w; }
  void expect(std::string_view punct) {
    if (!is(punct)) fail("expected '" + std::string(punct) + "'");
    advance();
  }
  [[noreturn]] void fail(const std::string& what) const {
    if (tok_.kind == Tok::End) throw Failure{"is cut short (" + what + " at the end)"};
    throw Failure{"line " + std::to_string(lineOf(tok_.offset)) + ": " + what + ", found '" +
                  std::string(tok_.text.substr(0, 40)) + "'"};
  }

  // A value; into `flat` when given (arrays of numbers or of tuples of numbers), else skipped.
  void value(Flat* flat, int depth = 0) {
    if (depth > 64) fail("values nested too deep");
    if (tok_.kind == Tok::Number || tok_.kind == Tok::Word) {
      if (flat != nullptr) {
        if (tok_.kind == Tok::Word && tok_.text == "None") {
          flat->blocked = true;
        } else {
          flat->scalars.push_back(tok_.text);
        }
      }
      advance();
      return;
    }
    if (tok_.kind == Tok::String || tok_.kind == Tok::Path) {
      advance();
      return;
    }
    if (is("[") || is("(")) {
      const std::string close = is("[") ? "]" : ")";
      const bool tuple = close == ")";
      advance();
      std::size_t count = 0;
      while (!is(close)) {
        const std::size_t before = flat != nullptr ? flat->scalars.size() : 0;
        value(flat, depth + 1);
        if (flat != nullptr && !tuple && depth == 0) {
          const auto width = static_cast<int>(flat->scalars.size() - before);
          if (flat->width == 0) flat->width = width;
          if (width != flat->width) fail("an array whose elements differ in size");
        }
        ++count;
        if (is(",")) {
          advance();
        } else if (!is(close)) {
          fail("expected ',' or '" + close + "'");
        }
      }
      advance();
      if (flat != nullptr && tuple && depth == 0) flat->width = static_cast<int>(count);
      return;
    }
    if (is("{")) {  // a dictionary: skipped
      skipBalanced("{", "}");
      return;
    }
    fail("expected a value");
  }

  // ( metadata ): entries `name = value`, `doc strings`, list edits (`add name = value`).
  void metadata() {
    expect("(");
    while (!is(")")) {
      if (tok_.kind == Tok::String) {
        advance();
      } else if (tok_.kind == Tok::Word) {
        advance();
        if (tok_.kind == Tok::Word) advance();  // add / append / prepend / delete / reorder
        if (is("=")) {
          advance();
          value(nullptr);
        }
      } else {
        fail("expected metadata");
      }
      if (is(";")) advance();
    }
    advance();
  }

  // The layer's metadata as text (numbers and strings), for the time codes.
  std::map<std::string, std::string> layerMetadata() {
    std::map<std::string, std::string> out;
    if (!is("(")) return out;
    advance();
    while (!is(")")) {
      if (tok_.kind == Tok::String) {
        advance();
        continue;
      }
      if (tok_.kind != Tok::Word) fail("expected layer metadata");
      const std::string key(take().text);
      if (tok_.kind == Tok::Word) advance();
      if (!is("=")) continue;
      advance();
      if (tok_.kind == Tok::Number || tok_.kind == Tok::String || tok_.kind == Tok::Word) {
        out[key] = std::string(tok_.text);
      }
      value(nullptr);
      if (is(";")) advance();
    }
    advance();
    return out;
  }

  void skipBalanced(std::string_view open, std::string_view close) {
    int depth = 0;
    do {
      if (tok_.kind == Tok::End) fail("expected '" + std::string(close) + "'");
      if (is(open)) ++depth;
      if (is(close)) --depth;
      advance();
    } while (depth > 0);
  }

  std::string_view text() const { return text_; }

 private:
  void advance() {
    tok_ = lex_.next();
    if (tok_.kind == Tok::End && lex_.offset() < text_.size()) {
      throw Failure{"line " + std::to_string(lineOf(lex_.offset())) +
                    ": a string or path is not closed"};
    }
  }
  std::size_t lineOf(std::size_t offset) const {
    return 1 +
           static_cast<std::size_t>(std::count(
               text_.begin(),
               text_.begin() + static_cast<std::ptrdiff_t>(std::min(offset, text_.size())), '\n'));
  }

  Lexer lex_;
  std::string_view text_;
  Token tok_;
};

// ---- the layer ---------------------------------------------------------------------------------

struct Attribute {
  std::string type;  // "point3f[]"
  std::string name;
  std::optional<Flat> sample;  // at the frame asked for
};

struct Layer {
  std::map<std::string, std::string> metadata;
  std::vector<Attribute> attributes;  // of the first Points prim, in file order
  std::vector<std::int64_t> times;    // of its points
  bool foundPoints = false;
};

const char* const kSpecifiers[] = {"def", "over", "class"};

bool isSpecifier(const Parser& p) {
  return std::any_of(std::begin(kSpecifiers), std::end(kSpecifiers),
                     [&](const char* s) { return p.isWord(s); });
}

std::int64_t timeOf(const Parser& p, std::string_view text) {
  double t = 0.0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), t);
  if (ec != std::errc() || end != text.data() + text.size() || t != std::floor(t)) {
    p.fail("a time code that is not a whole frame");
  }
  return static_cast<std::int64_t>(t);
}

// A prim's body; `keep` when it is the Points prim read (its attributes kept), else skipped.
void primBody(Parser& p, Layer& layer, bool keep, std::int64_t frame, int depth) {
  if (depth > 64) p.fail("prims nested too deep");
  p.expect("{");
  while (!p.is("}")) {
    if (isSpecifier(p)) {
      p.take();
      if (p.peek().kind == Tok::Word) p.take();  // the type
      if (p.peek().kind != Tok::String) p.fail("expected the prim's name");
      p.take();
      if (p.is("(")) p.metadata();
      primBody(p, layer, false, frame, depth + 1);
      continue;
    }
    if (p.isWord("rel")) {
      p.take();
      p.take();  // its name
      if (p.is("=")) {
        p.take();
        p.value(nullptr);
      }
      if (p.is("(")) p.metadata();
      continue;
    }
    if (p.isWord("variantSet")) {
      p.take();
      p.take();
      p.expect("=");
      p.skipBalanced("{", "}");
      continue;
    }
    // An attribute: [custom] [uniform|varying] TYPE[[]] NAME [.timeSamples | .connect] [= value]
    // [( metadata )].
    while (p.isWord("custom") || p.isWord("uniform") || p.isWord("varying")) p.take();
    if (p.peek().kind != Tok::Word) p.fail("expected an attribute's type");
    std::string type(p.take().text);
    if (p.is("[")) {
      p.take();
      p.expect("]");
      type += "[]";
    }
    if (p.peek().kind != Tok::Word) p.fail("expected an attribute's name");
    const std::string name(p.take().text);
    std::string field;
    if (p.is(".")) {
      p.take();
      if (p.peek().kind != Tok::Word) p.fail("expected timeSamples or connect");
      field = std::string(p.take().text);
    }
    Attribute* a = nullptr;
    if (keep) {
      auto it = std::find_if(layer.attributes.begin(), layer.attributes.end(),
                             [&](const Attribute& x) { return x.name == name; });
      if (it == layer.attributes.end()) {
        layer.attributes.push_back({type, name, std::nullopt});
        it = layer.attributes.end() - 1;
      }
      a = &*it;
    }
    if (p.is("=")) {
      p.take();
      if (field == "timeSamples") {
        p.expect("{");
        while (!p.is("}")) {
          if (p.peek().kind != Tok::Number) p.fail("expected a time code");
          const std::int64_t t = timeOf(p, p.take().text);
          p.expect(":");
          const bool wanted = a != nullptr && t == frame;
          Flat flat;
          p.value(wanted ? &flat : nullptr);
          if (wanted) a->sample = std::move(flat);
          if (a != nullptr && name == "points") layer.times.push_back(t);
          if (p.is(",")) p.take();
        }
        p.take();
      } else {
        p.value(nullptr);  // a default or a connection: not a frame's sample
      }
    }
    if (p.is("(")) p.metadata();
    if (p.is(";")) p.take();
  }
  p.take();
}

Layer parseLayer(std::string_view text, std::int64_t frame) {
  constexpr std::string_view kMagic = "#usda 1.0";
  if (text.substr(0, kMagic.size()) != kMagic) {
    throw Failure{"is not a USD text layer (it does not start with '#usda 1.0')"};
  }
  Parser p(text.substr(0));
  Layer layer;
  layer.metadata = p.layerMetadata();
  while (p.peek().kind != Tok::End) {
    if (!isSpecifier(p)) p.fail("expected a prim (def, over or class)");
    p.take();
    std::string type;
    if (p.peek().kind == Tok::Word) type = std::string(p.take().text);
    if (p.peek().kind != Tok::String) p.fail("expected the prim's name");
    p.take();
    if (p.is("(")) p.metadata();
    const bool keep = type == "Points" && !layer.foundPoints;
    primBody(p, layer, keep, frame, 0);
    layer.foundPoints = layer.foundPoints || keep;
  }
  if (!layer.foundPoints) throw Failure{"holds no Points prim"};
  return layer;
}

std::string readWhole(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path.string() + ": cannot open");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

template <typename T>
T number(std::string_view text, const std::string& what) {
  T v{};
  const char* first = text.data();
  const char* last = text.data() + text.size();
  if constexpr (std::is_floating_point_v<T>) {
    // USD writes the non-finite as inf, -inf and nan.
    if (text == "inf" || text == "+inf") return std::numeric_limits<T>::infinity();
    if (text == "-inf") return -std::numeric_limits<T>::infinity();
    if (text == "nan" || text == "-nan") return std::numeric_limits<T>::quiet_NaN();
  }
  if (!text.empty() && text[0] == '+') ++first;
  const auto [end, ec] = std::from_chars(first, last, v);
  if (ec != std::errc() || end != last) {
    throw Failure{what + ": '" + std::string(text.substr(0, 40)) + "' is not a number"};
  }
  return v;
}

}  // namespace

FrameData readUsdaFrame(const std::filesystem::path& path, std::int64_t frame) {
  try {
    const std::string text = readWhole(path);
    const Layer layer = parseLayer(text, frame);
    const auto find = [&](const std::string& name) -> const Attribute* {
      for (const Attribute& a : layer.attributes) {
        if (a.name == name) return &a;
      }
      return nullptr;
    };
    const Attribute* ids = find("ids");
    if (ids == nullptr || !ids->sample) {
      throw Failure{"has no ids at frame " + std::to_string(frame)};
    }
    const std::size_t n = ids->sample->scalars.size();
    // Each attribute's sample at the frame, checked for one element a point of `width` numbers.
    const auto sampleOf = [&](const Attribute& a, int width) -> const Flat& {
      if (!a.sample || a.sample->blocked) {
        throw Failure{a.name + " has no sample at frame " + std::to_string(frame)};
      }
      const Flat& f = *a.sample;
      if (f.scalars.size() != n * static_cast<std::size_t>(width) || (n > 0 && f.width != width)) {
        throw Failure{a.name + " has " + std::to_string(f.scalars.size()) + " numbers at frame " +
                      std::to_string(frame) + " (expected " + std::to_string(n) + " of " +
                      std::to_string(width) + ")"};
      }
      return f;
    };
    const auto floats = [&](const Flat& f, int component, int width, FloatColumn& out) {
      for (std::size_t i = 0; i < n; ++i) {
        out[static_cast<Eigen::Index>(i)] = number<float>(
            f.scalars[i * static_cast<std::size_t>(width) + static_cast<std::size_t>(component)],
            "a value");
      }
    };
    // Each attribute column of the frame: the layer's attribute, the component read of its
    // `width` numbers a point, and whether it is a diameter (widths: pscale is half).
    struct Source {
      const Attribute* attribute;
      int component, width;
      bool halved;
    };
    std::vector<std::string> names;
    std::vector<Source> sources;
    const auto add = [&](const Attribute& a, const std::string& column) {
      const bool vector = a.type == "vector3f[]" || a.type == "float3[]" || a.type == "color3f[]" ||
                          a.type == "point3f[]" || a.type == "normal3f[]";
      if (!vector) {
        names.push_back(column);
        sources.push_back({&a, 0, 1, a.name == "widths"});
        return;
      }
      const std::array<std::string, 3> components = vectorColumns(column);
      for (int c = 0; c < 3; ++c) {
        names.push_back(components[static_cast<std::size_t>(c)]);
        sources.push_back({&a, c, 3, false});
      }
    };
    for (const Attribute& a : layer.attributes) {
      const std::string& name = a.name;
      if (name == "points" || name == "velocities" || name == "ids" || name == "primvars:age" ||
          name == "primvars:life" || name == "primvars:mass") {
        continue;
      }
      if (name == "widths") {
        add(a, "pscale");
      } else if (name == "primvars:displayColor") {
        add(a, "Cd");
      } else if (name == "primvars:displayOpacity") {
        add(a, "Alpha");
      } else if (name.rfind("primvars:", 0) == 0) {
        add(a, name.substr(9));
      }
    }
    FrameData data;
    data.resize(n, names);
    data.frame = frame;
    if (const auto it = layer.metadata.find("timeCodesPerSecond"); it != layer.metadata.end()) {
      data.timeSeconds =
          static_cast<double>(frame) / number<double>(it->second, "timeCodesPerSecond");
    }
    for (std::size_t i = 0; i < n; ++i) {
      data.id[i] = number<std::uint64_t>(ids->sample->scalars[i], "an id");
    }
    const auto required = [&](const char* name) -> const Attribute& {
      const Attribute* a = find(name);
      if (a == nullptr) throw Failure{"has no " + std::string(name)};
      return *a;
    };
    const Flat& p = sampleOf(required("points"), 3);
    const Flat& v = sampleOf(required("velocities"), 3);
    for (int c = 0; c < 3; ++c) {
      floats(p, c, 3, data.position[c]);
      floats(v, c, 3, data.velocity[c]);
    }
    floats(sampleOf(required("primvars:age"), 1), 0, 1, data.age);
    floats(sampleOf(required("primvars:life"), 1), 0, 1, data.life);
    floats(sampleOf(required("primvars:mass"), 1), 0, 1, data.mass);
    for (std::size_t k = 0; k < sources.size(); ++k) {
      const Source& s = sources[k];
      const Attribute& a = *s.attribute;
      const Flat& f = sampleOf(a, s.width);
      FloatColumn& out = data.attributes[k];
      if (a.type == "int[]") {
        for (std::size_t i = 0; i < n; ++i) {
          out[static_cast<Eigen::Index>(i)] =
              static_cast<float>(number<std::int64_t>(f.scalars[i], a.name));
        }
      } else {
        floats(f, s.component, s.width, out);
        if (s.halved) out *= 0.5f;  // widths are diameters: halved exactly
      }
    }
    return data;
  } catch (const Failure& f) {
    throw std::runtime_error(path.string() + ": " + f.what);
  }
}

std::vector<std::int64_t> usdaFrames(const std::filesystem::path& path) {
  try {
    const std::string text = readWhole(path);
    return parseLayer(text, std::numeric_limits<std::int64_t>::min()).times;
  } catch (const Failure& f) {
    throw std::runtime_error(path.string() + ": " + f.what);
  }
}

}  // namespace tickfx::io
