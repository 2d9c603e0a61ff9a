#include "io/cache/PlyCache.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "io/cache/AttributeGroups.h"
#include "io/cache/RowBlocks.h"
#include "io/util/AtomicFile.h"

namespace tickfx::io {
namespace {

static_assert(std::endian::native == std::endian::little,
              "PLY caches are written little-endian by copying memory");

constexpr std::size_t kPlyRowsPerBlock = 32768;

const char* const kFixedFloats[] = {"x", "y", "z", "vx", "vy", "vz", "age", "life", "mass"};
constexpr std::size_t kStandardColumns = std::size(kFixedFloats);

// The PLY convention's names for Houdini's colour and opacity (red, green, blue, alpha: floats,
// linear, as the frame holds them); every other attribute keeps its name.
const std::pair<const char*, const char*> kPlyNames[] = {
    {"Cd_r", "red"}, {"Cd_g", "green"}, {"Cd_b", "blue"}, {"Alpha", "alpha"}};

std::string plyName(const std::string& column) {
  for (const auto& [ours, ply] : kPlyNames) {
    if (column == ours) return ply;
  }
  return column;
}

std::string columnName(const std::string& property) {
  for (const auto& [ours, ply] : kPlyNames) {
    if (property == ply) return ours;
  }
  return property;
}

#if defined(__SSE2__)
// The id and the standard columns (`cols`' first, in their order) of rows [begin, end) at
// `bytes`, `rowBytes` apart, a row at a time: its 44 bytes are made in registers and stored by
// three 16-byte stores. A pass a column stored each value alone, ten 4-byte stores a row at a
// stride of a row: the stores, not the reads, bounded it. The third store reaches 4 bytes past
// the standard columns: into the row's other columns, stored after it, or else into the next
// row's id, stored after it too; the block's last row without other columns stores its last 12
// bytes alone.
void standardRows(const std::uint64_t* __restrict id, const std::vector<const FloatColumn*>& cols,
                  std::size_t rowBytes, std::size_t begin, std::size_t end, char* bytes) {
  static_assert(kStandardColumns == 9, "three 16-byte stores: the id and nine floats");
  std::array<const float*, kStandardColumns> column{};
  for (std::size_t c = 0; c < kStandardColumns; ++c) column[c] = cols[c]->data();
  constexpr std::size_t kBytes = sizeof(double) + kStandardColumns * sizeof(float);
  const bool spills = rowBytes < kBytes + sizeof(float);
  // Bit moves only (no arithmetic on the floats): NaN payloads go out as they are.
  const auto one = [&](std::size_t c, std::size_t i) { return _mm_load_ss(column[c] + i); };
  const auto pair = [&](std::size_t c, std::size_t i) {
    return _mm_unpacklo_ps(one(c, i), one(c + 1, i));
  };
  char* __restrict to = bytes;
  for (std::size_t i = begin; i < end; ++i, to += rowBytes) {
    const __m128 idBits = _mm_castpd_ps(_mm_set_sd(static_cast<double>(id[i])));
    _mm_storeu_ps(reinterpret_cast<float*>(to), _mm_movelh_ps(idBits, pair(0, i)));
    _mm_storeu_ps(reinterpret_cast<float*>(to + 16), _mm_movelh_ps(pair(2, i), pair(4, i)));
    const __m128 last = _mm_movelh_ps(pair(6, i), one(8, i));
    if (i + 1 < end || !spills) {
      _mm_storeu_ps(reinterpret_cast<float*>(to + 32), last);
    } else {
      _mm_storel_pi(reinterpret_cast<__m64*>(to + 32), last);
      std::memcpy(to + 40, column[8] + i, sizeof(float));
    }
  }
}
#endif

// The columns of a row after its id, in the file's order: the standard ones (kFixedFloats), then
// the frame's attributes. For the writer (const) and the reader alike.
template <typename Frame>
auto floatColumns(Frame& f) {
  using Column = std::conditional_t<std::is_const_v<Frame>, const FloatColumn, FloatColumn>;
  std::vector<Column*> cols = {&f.position.x, &f.position.y, &f.position.z,
                               &f.velocity.x, &f.velocity.y, &f.velocity.z,
                               &f.age,        &f.life,       &f.mass};
  for (Column& a : f.attributes) cols.push_back(&a);
  return cols;
}

// Float columns [first, last) of `cols` of rows [begin, end) at `bytes`, `rowBytes` apart, each
// at its place in the row (after the id). With SSE2, four columns a pass, each row's four values
// put together in a register and stored by one 16-byte store, then a pair by one 8-byte store:
// four passes of one 4-byte store a row at a stride of a row cost four times the stores. What is
// left goes a column a pass. Bit moves only, as above: NaN payloads go out as they are.
void storeFloatColumns(const std::vector<const FloatColumn*>& cols, std::size_t first,
                       std::size_t last, std::size_t rowBytes, std::size_t begin, std::size_t end,
                       char* bytes) {
  std::size_t c = first;
#if defined(__SSE2__)
  for (; c + 4 <= last; c += 4) {
    const float* __restrict a = cols[c]->data();
    const float* __restrict b = cols[c + 1]->data();
    const float* __restrict d = cols[c + 2]->data();
    const float* __restrict e = cols[c + 3]->data();
    char* __restrict to = bytes + sizeof(double) + c * sizeof(float);
    for (std::size_t i = begin; i < end; ++i, to += rowBytes) {
      const __m128 ab = _mm_unpacklo_ps(_mm_load_ss(a + i), _mm_load_ss(b + i));
      const __m128 de = _mm_unpacklo_ps(_mm_load_ss(d + i), _mm_load_ss(e + i));
      _mm_storeu_ps(reinterpret_cast<float*>(to), _mm_movelh_ps(ab, de));
    }
  }
  if (c + 2 <= last) {
    const float* __restrict a = cols[c]->data();
    const float* __restrict b = cols[c + 1]->data();
    char* __restrict to = bytes + sizeof(double) + c * sizeof(float);
    for (std::size_t i = begin; i < end; ++i, to += rowBytes) {
      _mm_storel_pi(reinterpret_cast<__m64*>(to),
                    _mm_unpacklo_ps(_mm_load_ss(a + i), _mm_load_ss(b + i)));
    }
    c += 2;
  }
#endif
  for (; c < last; ++c) {
    const float* __restrict a = cols[c]->data();
    char* __restrict to = bytes + sizeof(double) + c * sizeof(float);
    for (std::size_t i = begin; i < end; ++i, to += rowBytes) std::memcpy(to, a + i, sizeof(float));
  }
}

// Rows [begin, end) at `bytes`, `rowBytes` apart: each row's id (as a double), then its floats
// (ints where `ints` says), in the order of `cols`, the standard columns first.
void formatRows(const FrameData& frame, const std::vector<const FloatColumn*>& cols,
                const std::vector<bool>& ints, std::size_t rowBytes, std::size_t begin,
                std::size_t end, char* bytes) {
  std::size_t c = 0;
#if defined(__SSE2__)
  standardRows(frame.id.data(), cols, rowBytes, begin, end, bytes);
  c = kStandardColumns;
#else
  for (std::size_t i = begin; i < end; ++i) {
    const double id = static_cast<double>(frame.id[i]);
    std::memcpy(bytes + (i - begin) * rowBytes, &id, sizeof id);
  }
#endif
  // The others: each run of float columns together, each int column alone.
  while (c < cols.size()) {
    if (!ints[c]) {
      std::size_t last = c + 1;
      while (last < cols.size() && !ints[last]) ++last;
      storeFloatColumns(cols, c, last, rowBytes, begin, end, bytes);
      c = last;
      continue;
    }
    const float* const column = cols[c]->data();
    char* at = bytes + sizeof(double) + c * sizeof(float);
    for (std::size_t i = begin; i < end; ++i, at += rowBytes) {
      const auto v = static_cast<std::int32_t>(column[i]);
      std::memcpy(at, &v, sizeof v);
    }
    ++c;
  }
}

}  // namespace

void writePlyCache(const FrameData& frame, const std::filesystem::path& path,
                   Durability durability) {
  std::ostringstream header;
  header << "ply\nformat binary_little_endian 1.0\n";
  header << "comment tickfx frame " << frame.frame << "\n";
  char time[64];
  std::snprintf(time, sizeof time, "%.17g", frame.timeSeconds);
  header << "comment time " << time << "\n";
  header << "element vertex " << frame.size() << "\n";
  header << "property double id\n";
  for (const char* name : kFixedFloats) header << "property float " << name << "\n";
  for (const std::string& name : frame.attributeNames)
    header << "property " << (isIntAttribute(name) ? "int " : "float ") << plyName(name) << "\n";
  header << "end_header\n";
  const std::string head = std::move(header).str();
  const std::vector<const FloatColumn*> cols = floatColumns(frame);
  // Houdini's integers (hitnum) as 32-bit ints: their columns hold whole numbers.
  std::vector<bool> ints(cols.size(), false);
  for (std::size_t a = 0; a < frame.attributeNames.size(); ++a)
    ints[kStandardColumns + a] = isIntAttribute(frame.attributeNames[a]);
  const std::size_t rowBytes = sizeof(double) + cols.size() * sizeof(float);
  writeFileAtomically(
      path,
      [&](std::ostream& out) {
        out.write(head.data(), static_cast<std::streamsize>(head.size()));
        writeRowsInBlocks(out, frame.size(), kPlyRowsPerBlock, rowBytes,
                          [&](std::size_t begin, std::size_t end, char* bytes) {
                            formatRows(frame, cols, ints, rowBytes, begin, end, bytes);
                            return (end - begin) * rowBytes;
                          });
      },
      durability, head.size() + frame.size() * rowBytes);
}

FrameData readPlyCache(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path.string() + ": cannot open");
  auto fail = [&](const std::string& what) {
    throw std::runtime_error(path.string() + ": " + what);
  };
  std::string line;
  if (!std::getline(in, line) || line != "ply") fail("not a PLY file");
  if (!std::getline(in, line) || line != "format binary_little_endian 1.0")
    fail("not binary little-endian PLY");
  FrameData frame;
  std::size_t count = 0;
  std::vector<std::string> floats;  // every 4-byte property, floats and ints
  std::vector<bool> ints;
  bool sawId = false;
  while (std::getline(in, line) && line != "end_header") {
    std::istringstream words(line);
    std::string word, type, name;
    words >> word;
    if (word == "comment") {
      words >> name;
      if (name == "tickfx") words >> name;  // "comment tickfx frame N"
      if (name == "frame") words >> frame.frame;
      if (name == "time") words >> frame.timeSeconds;
    } else if (word == "element") {
      words >> name >> count;
      if (name != "vertex") fail("unexpected element '" + name + "'");
    } else if (word == "property") {
      words >> type >> name;
      if (type == "double" && name == "id" && floats.empty()) {
        sawId = true;
      } else if ((type == "float" || (type == "int" && floats.size() >= kStandardColumns)) &&
                 !name.empty()) {
        floats.push_back(floats.size() >= kStandardColumns ? columnName(name) : name);
        ints.push_back(type == "int");
      } else {
        fail("unexpected property '" + line + "'");
      }
    } else {
      fail("unexpected header line '" + line + "'");
    }
  }
  if (line != "end_header" || !sawId || floats.size() < kStandardColumns) fail("incomplete header");
  for (std::size_t k = 0; k < kStandardColumns; ++k) {
    if (floats[k] != kFixedFloats[k]) fail("unexpected property order at '" + floats[k] + "'");
  }
  // The body's size is known from the header: checked against the file before any row is
  // allocated, so a damaged count is a message, not an allocation of its size.
  const std::size_t rowBytes = sizeof(double) + floats.size() * sizeof(float);
  const std::streamoff bodyStart = in.tellg();
  in.seekg(0, std::ios::end);
  const std::streamoff fileEnd = in.tellg();
  in.seekg(bodyStart);
  const auto bodyBytes = static_cast<std::uint64_t>(fileEnd - bodyStart);
  if (count > bodyBytes / rowBytes) {
    fail("truncated body (" + std::to_string(count) + " vertices of " + std::to_string(rowBytes) +
         " bytes, " + std::to_string(bodyBytes) + " bytes after the header)");
  }
  frame.resize(count, std::vector<std::string>(floats.begin() + kStandardColumns, floats.end()));
  const std::vector<FloatColumn*> cols = floatColumns(frame);
  std::vector<char> row(rowBytes);
  for (std::size_t i = 0; i < count; ++i) {
    if (!in.read(row.data(), static_cast<std::streamsize>(row.size()))) fail("truncated body");
    double id = 0;
    std::memcpy(&id, row.data(), sizeof id);
    // Ids are written as doubles (exact below 2⁵³); anything else is not an id.
    if (!(id >= 0.0 && id < 0x1p64 && id == std::floor(id))) {
      char text[40];
      std::snprintf(text, sizeof text, "%.17g", id);
      fail("vertex " + std::to_string(i) + ": id " + text + " is not a whole number in [0, 2^64)");
    }
    frame.id[i] = static_cast<std::uint64_t>(id);
    for (std::size_t c = 0; c < cols.size(); ++c) {
      const char* at = row.data() + sizeof(double) + c * sizeof(float);
      float& value = (*cols[c])[static_cast<Eigen::Index>(i)];
      if (ints[c]) {
        std::int32_t v = 0;
        std::memcpy(&v, at, sizeof v);
        value = static_cast<float>(v);
      } else {
        std::memcpy(&value, at, sizeof(float));
      }
    }
  }
  return frame;
}

}  // namespace tickfx::io
