#include "io/CsvCache.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "io/AtomicFile.h"

namespace tickfx::io {
namespace {

constexpr const char* kFixedHeader = "id,px,py,pz,vx,vy,vz,age,life,mass";
constexpr int kFixedFloatColumns = 9;

void appendFloat(std::string& line, float value) {
  // printf spells a NaN with its sign bit "-nan", which most CSV readers refuse: one spelling.
  if (std::isnan(value)) {
    line += ",nan";
    return;
  }
  char text[32];
  std::snprintf(text, sizeof text, ",%.9g", static_cast<double>(value));
  line += text;
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

void writeCsvCache(const FrameData& frame, const std::filesystem::path& path) {
  writeFileAtomically(path, [&](std::ostream& out) {
    std::string line = kFixedHeader;
    for (const std::string& name : frame.attributeNames) line += "," + name;
    out << line << '\n';
    for (std::size_t i = 0; i < frame.size(); ++i) {
      const auto r = static_cast<Eigen::Index>(i);
      line = std::to_string(frame.id[i]);
      for (int c = 0; c < 3; ++c) appendFloat(line, frame.position[c][r]);
      for (int c = 0; c < 3; ++c) appendFloat(line, frame.velocity[c][r]);
      appendFloat(line, frame.age[r]);
      appendFloat(line, frame.life[r]);
      appendFloat(line, frame.mass[r]);
      for (const FloatColumn& a : frame.attributes) appendFloat(line, a[r]);
      out << line << '\n';
    }
  });
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
    return FloatColumn(Eigen::Map<const FloatColumn>(values[k].data(), n));
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
