#include "io/mesh/MeshFile.h"

#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace tickfx::io {
namespace {

// Far more than any collider mesh, far less than memory: a hostile count is refused before any
// allocation it would size.
constexpr std::size_t kMaxElements = 50'000'000;

[[noreturn]] void fail(const std::string& label, const std::string& what) {
  throw std::runtime_error(label + ": " + what);
}

std::vector<std::string_view> words(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    const std::size_t b = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t' && line[i] != '\r') ++i;
    if (i > b) out.push_back(line.substr(b, i - b));
  }
  return out;
}

float toFloat(std::string_view w, const std::string& label, std::size_t line) {
  double v = 0.0;
  const auto r = std::from_chars(w.data(), w.data() + w.size(), v);
  if (r.ec != std::errc() || r.ptr != w.data() + w.size() || !std::isfinite(v) ||
      std::fabs(v) > 1e9) {
    fail(label, "line " + std::to_string(line) + ": \"" + std::string(w.substr(0, 40)) +
                    "\" is not a coordinate (expected a number from -1e9 to 1e9)");
  }
  return static_cast<float>(v);
}

TriangleMesh parseObj(std::string_view text, const std::string& label) {
  TriangleMesh mesh;
  std::size_t lineNo = 0, pos = 0;
  while (pos < text.size()) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    const std::string_view line = text.substr(pos, end - pos);
    pos = end + 1;
    ++lineNo;
    const std::vector<std::string_view> w = words(line);
    if (w.empty()) continue;
    if (w[0] == "v") {
      if (w.size() < 4) fail(label, "line " + std::to_string(lineNo) + ": a vertex needs x y z");
      if (mesh.points.size() >= kMaxElements) fail(label, "more than 50000000 vertices");
      mesh.points.emplace_back(toFloat(w[1], label, lineNo), toFloat(w[2], label, lineNo),
                               toFloat(w[3], label, lineNo));
    } else if (w[0] == "f") {
      if (w.size() < 4) {
        fail(label, "line " + std::to_string(lineNo) + ": a face needs at least 3 vertices");
      }
      std::vector<std::uint32_t> corners;
      for (std::size_t k = 1; k < w.size(); ++k) {
        const std::string_view index = w[k].substr(0, w[k].find('/'));
        long long i = 0;
        const auto r = std::from_chars(index.data(), index.data() + index.size(), i);
        const auto n = static_cast<long long>(mesh.points.size());
        if (r.ec != std::errc() || r.ptr != index.data() + index.size() || i == 0 || i > n ||
            i < -n) {
          fail(label, "line " + std::to_string(lineNo) + ": \"" + std::string(w[k].substr(0, 40)) +
                          "\" is not a vertex (expected 1 to " + std::to_string(n) +
                          ", or -1 to -" + std::to_string(n) + ")");
        }
        corners.push_back(static_cast<std::uint32_t>(i > 0 ? i - 1 : n + i));
      }
      if (mesh.triangles.size() + corners.size() > kMaxElements) {
        fail(label, "more than 50000000 triangles");
      }
      for (std::size_t k = 2; k < corners.size(); ++k) {
        mesh.triangles.push_back({corners[0], corners[k - 1], corners[k]});
      }
    }
  }
  return mesh;
}

// A PLY header's elements and the properties that matter.
struct PlyLayout {
  enum class Format { Ascii, Little, Big } format = Format::Ascii;
  struct Element {
    std::string name;
    std::size_t count = 0;
    struct Property {
      std::string name, type, countType;  // countType non-empty for a list
    };
    std::vector<Property> properties;
  };
  std::vector<Element> elements;
};

std::size_t typeSize(const std::string& t) {
  if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
  if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
  if (t == "int" || t == "uint" || t == "float" || t == "int32" || t == "uint32" || t == "float32")
    return 4;
  if (t == "double" || t == "float64") return 8;
  return 0;
}

class PlyReader {
 public:
  PlyReader(std::string_view bytes, const std::string& label, PlyLayout::Format format)
      : bytes_(bytes), label_(label), format_(format) {}
  std::size_t pos = 0;

  double number(const std::string& type) {
    if (format_ == PlyLayout::Format::Ascii) return asciiNumber();
    const std::size_t n = typeSize(type);
    if (pos + n > bytes_.size())
      fail(label_, "is truncated (the data ends at byte " + std::to_string(bytes_.size()) + ")");
    unsigned char b[8];
    std::memcpy(b, bytes_.data() + pos, n);
    pos += n;
    if ((format_ == PlyLayout::Format::Big) != (std::endian::native == std::endian::big)) {
      for (std::size_t i = 0; i < n / 2; ++i) std::swap(b[i], b[n - 1 - i]);
    }
    const auto get = [&b](auto v) {
      std::memcpy(&v, b, sizeof v);
      return static_cast<double>(v);
    };
    if (type == "char" || type == "int8") return get(std::int8_t{});
    if (type == "uchar" || type == "uint8") return get(std::uint8_t{});
    if (type == "short" || type == "int16") return get(std::int16_t{});
    if (type == "ushort" || type == "uint16") return get(std::uint16_t{});
    if (type == "int" || type == "int32") return get(std::int32_t{});
    if (type == "uint" || type == "uint32") return get(std::uint32_t{});
    if (type == "float" || type == "float32") return get(float{});
    return get(double{});
  }

 private:
  double asciiNumber() {
    while (pos < bytes_.size() && std::isspace(static_cast<unsigned char>(bytes_[pos]))) ++pos;
    const std::size_t b = pos;
    while (pos < bytes_.size() && !std::isspace(static_cast<unsigned char>(bytes_[pos]))) ++pos;
    if (b == pos) fail(label_, "is truncated (the data ends before its last element)");
    double v = 0.0;
    const auto r = std::from_chars(bytes_.data() + b, bytes_.data() + pos, v);
    if (r.ec != std::errc() || r.ptr != bytes_.data() + pos) {
      fail(label_, "\"" + std::string(bytes_.substr(b, std::min<std::size_t>(pos - b, 40))) +
                       "\" is not a number");
    }
    return v;
  }
  std::string_view bytes_;
  const std::string& label_;
  PlyLayout::Format format_;
};

TriangleMesh parsePly(std::string_view bytes, const std::string& label) {
  const std::size_t headerEnd = bytes.find("end_header");
  if (headerEnd == std::string_view::npos) fail(label, "is a PLY file without end_header");
  std::size_t dataStart = bytes.find('\n', headerEnd);
  dataStart = dataStart == std::string_view::npos ? bytes.size() : dataStart + 1;
  PlyLayout layout;
  std::istringstream header{std::string(bytes.substr(0, headerEnd))};
  std::string line;
  bool formatSeen = false;
  while (std::getline(header, line)) {
    const std::vector<std::string_view> w = words(line);
    if (w.empty()) continue;
    if (w[0] == "format" && w.size() >= 2) {
      formatSeen = true;
      if (w[1] == "ascii") {
        layout.format = PlyLayout::Format::Ascii;
      } else if (w[1] == "binary_little_endian") {
        layout.format = PlyLayout::Format::Little;
      } else if (w[1] == "binary_big_endian") {
        layout.format = PlyLayout::Format::Big;
      } else {
        fail(label, "has PLY format \"" + std::string(w[1].substr(0, 40)) + "\"");
      }
    } else if (w[0] == "element" && w.size() >= 3) {
      std::size_t count = 0;
      const auto r = std::from_chars(w[2].data(), w[2].data() + w[2].size(), count);
      if (r.ec != std::errc() || count > kMaxElements) {
        fail(label, "element " + std::string(w[1].substr(0, 40)) + " has count \"" +
                        std::string(w[2].substr(0, 40)) + "\" (expected 0 to 50000000)");
      }
      layout.elements.push_back({std::string(w[1]), count, {}});
    } else if (w[0] == "property" && !layout.elements.empty()) {
      auto& props = layout.elements.back().properties;
      if (w.size() >= 5 && w[1] == "list") {
        props.push_back({std::string(w[4]), std::string(w[3]), std::string(w[2])});
      } else if (w.size() >= 3 && w[1] != "list") {
        props.push_back({std::string(w[2]), std::string(w[1]), ""});
      } else {
        fail(label,
             "has a property line without a type and a name (expected property TYPE "
             "NAME or property list COUNT_TYPE TYPE NAME)");
      }
      const auto& p = props.back();
      if (typeSize(p.type) == 0 || (!p.countType.empty() && typeSize(p.countType) == 0)) {
        fail(label, "property " + p.name + " has an unknown type");
      }
    }
  }
  if (!formatSeen) fail(label, "is a PLY file without a format line");
  TriangleMesh mesh;
  PlyReader in(bytes, label, layout.format);
  in.pos = dataStart;
  for (const auto& e : layout.elements) {
    for (std::size_t i = 0; i < e.count; ++i) {
      Eigen::Vector3f p = Eigen::Vector3f::Zero();
      for (const auto& prop : e.properties) {
        if (!prop.countType.empty()) {
          const double n = in.number(prop.countType);
          if (!(n >= 0.0 && n <= 1000.0)) {
            fail(label, e.name + " " + std::to_string(i) + " has a list of " + std::to_string(n) +
                            " items (expected 0 to 1000)");
          }
          std::vector<std::uint32_t> corners;
          for (int k = 0; k < static_cast<int>(n); ++k) {
            const double v = in.number(prop.type);
            if (e.name == "face" &&
                (prop.name == "vertex_indices" || prop.name == "vertex_index")) {
              if (!(v >= 0.0 && v < 4294967295.0) || v != std::floor(v)) {
                fail(label, "face " + std::to_string(i) + " has index " + std::to_string(v));
              }
              corners.push_back(static_cast<std::uint32_t>(v));
            }
          }
          for (std::size_t k = 2; k < corners.size(); ++k) {
            mesh.triangles.push_back({corners[0], corners[k - 1], corners[k]});
          }
          continue;
        }
        const double v = in.number(prop.type);
        if (e.name != "vertex") continue;
        const int c = prop.name == "x" ? 0 : prop.name == "y" ? 1 : prop.name == "z" ? 2 : -1;
        if (c < 0) continue;
        if (!(std::isfinite(v) && std::fabs(v) <= 1e9)) {
          fail(label, "vertex " + std::to_string(i) + " has coordinate " + std::to_string(v) +
                          " (expected -1e9 to 1e9)");
        }
        p[c] = static_cast<float>(v);
      }
      if (e.name == "vertex") mesh.points.push_back(p);
    }
  }
  return mesh;
}

}  // namespace

TriangleMesh parseMesh(std::string_view bytes, const std::string& label) {
  if (bytes.empty()) fail(label, "is empty (expected an OBJ or PLY triangle mesh)");
  TriangleMesh mesh = bytes.substr(0, 3) == "ply" ? parsePly(bytes, label) : parseObj(bytes, label);
  if (mesh.triangles.empty())
    fail(label, "has no triangles (expected an OBJ or PLY triangle mesh)");
  return mesh;
}

TriangleMesh readMeshFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, "no such file (expected an OBJ or PLY triangle mesh)");
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return parseMesh(bytes, path);
}

}  // namespace tickfx::io
