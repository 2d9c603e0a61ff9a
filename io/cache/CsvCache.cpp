#include "io/cache/CsvCache.h"

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "io/cache/RowBlocks.h"
#include "io/util/AtomicFile.h"

namespace tickfx::io {
namespace {

constexpr const char* kFixedHeader = "id,px,py,pz,vx,vy,vz,age,life,mass";
constexpr int kFixedFloatColumns = 9;

// The longest shortest-round-trip float is "-1.17549435e-38" (15 characters); an id has at most
// 20 digits.
constexpr std::size_t kMaxFloatChars = 16;
constexpr std::size_t kMaxIdChars = 20;
constexpr std::size_t kCsvRowsPerBlock = 16384;

char* putFloat(char* p, float value) {
  *p++ = ',';
  // A NaN has one spelling whatever its sign or payload ("-nan" is refused by most CSV readers).
  if (std::isnan(value)) {
    std::memcpy(p, "nan", 3);
    return p + 3;
  }
  return std::to_chars(p, p + kMaxFloatChars, value).ptr;
}

std::vector<std::string> splitCommas(const std::string& line) {
  std::vector<std::string> fields;
  std::stringstream stream(line);
  std::string field;
  while (std::getline(stream, field, ',')) fields.push_back(field);
  if (!line.empty() && line.back() == ',') fields.emplace_back();
  return fields;
}

}  // namespace

void writeCsvCache(const FrameData& frame, const std::filesystem::path& path,
                   Durability durability) {
  std::vector<const FloatColumn*> columns = {
      &frame.position.x, &frame.position.y, &frame.position.z, &frame.velocity.x, &frame.velocity.y,
      &frame.velocity.z, &frame.age,        &frame.life,       &frame.mass};
  for (const FloatColumn& a : frame.attributes) columns.push_back(&a);
  const std::size_t maxRowChars = kMaxIdChars + columns.size() * kMaxFloatChars + 1;
  writeFileAtomically(
      path,
      [&](std::ostream& out) {
        std::string header = kFixedHeader;
        for (const std::string& name : frame.attributeNames) header += "," + name;
        out << header << '\n';
        writeRowsInBlocks(out, frame.size(), kCsvRowsPerBlock, maxRowChars,
                          [&](std::size_t begin, std::size_t end, char* bytes) {
                            char* p = bytes;
                            for (std::size_t i = begin; i < end; ++i) {
                              const auto r = static_cast<Eigen::Index>(i);
                              p = std::to_chars(p, p + kMaxIdChars, frame.id[i]).ptr;
                              for (const FloatColumn* c : columns) p = putFloat(p, (*c)[r]);
                              *p++ = '\n';
                            }
                            return static_cast<std::size_t>(p - bytes);
                          });
      },
      durability);
}

FrameData readCsvCache(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path.string() + ": cannot open");
  auto fail = [&](std::size_t line, const std::string& what) {
    throw std::runtime_error(path.string() + ":" + std::to_string(line) + ": " + what);
  };
  std::string line;
  // Lines may end in CRLF (a cache that went through a Windows tool): the CR is not part of the
  // last field.
  const auto next = [&] {
    if (!std::getline(in, line)) return false;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    return true;
  };
  if (!next() || line.rfind(kFixedHeader, 0) != 0) fail(1, "not a tickfx CSV cache header");
  FrameData frame;
  const std::vector<std::string> header = splitCommas(line);
  frame.attributeNames.assign(header.begin() + 1 + kFixedFloatColumns, header.end());
  const std::size_t columns = header.size();

  std::vector<std::vector<float>> values(columns - 1);
  std::size_t lineNumber = 1;
  while (next()) {
    ++lineNumber;
    const std::vector<std::string> fields = splitCommas(line);
    if (fields.size() != columns)
      fail(lineNumber, "expected " + std::to_string(columns) + " fields");
    char* end = nullptr;
    errno = 0;
    const unsigned long long id = std::strtoull(fields[0].c_str(), &end, 10);
    if (errno != 0 || *end != '\0' || fields[0].empty())
      fail(lineNumber, "bad id '" + fields[0] + "'");
    frame.id.push_back(id);
    for (std::size_t f = 1; f < columns; ++f) {
      const float v = std::strtof(fields[f].c_str(), &end);
      if (*end != '\0' || fields[f].empty()) fail(lineNumber, "bad number '" + fields[f] + "'");
      values[f - 1].push_back(v);
    }
  }
  const auto n = static_cast<Eigen::Index>(frame.id.size());
  auto column = [&](std::size_t k) {
    return FloatColumn(Eigen::Map<const Eigen::ArrayXf>(values[k].data(), n));
  };
  for (int c = 0; c < 3; ++c) frame.position[c] = column(static_cast<std::size_t>(c));
  for (int c = 0; c < 3; ++c) frame.velocity[c] = column(static_cast<std::size_t>(3 + c));
  frame.age = column(6);
  frame.life = column(7);
  frame.mass = column(8);
  for (std::size_t a = 0; a < frame.attributeNames.size(); ++a)
    frame.attributes.push_back(column(kFixedFloatColumns + a));
  return frame;
}

}  // namespace tickfx::io
