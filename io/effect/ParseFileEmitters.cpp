#include "io/effect/ParseFileEmitters.h"

#include <cctype>
#include <charconv>
#include <exception>
#include <filesystem>
#include <string>
#include <system_error>
#include <utility>

#include "io/cache/CsvCache.h"
#include "io/cache/FrameData.h"
#include "io/cache/VdbPointCache.h"
#include "io/effect/EmitterKeys.h"
#include "io/effect/ParseEmitters.h"

namespace tickfx::io::detail {
namespace {

const std::string kPointFileText =
    "a points file relative to the effect file: .vdb (OpenVDB points, grid \"points\") or .csv "
    "(a tickfx CSV cache)";

// "[x, y, z]" with the shortest digits that read back to each float ("1e+30", not the double's
// "1.0000000150474662e+30").
std::string vectorText(const Eigen::Vector3f& v) {
  std::string out = "[";
  for (int c = 0; c < 3; ++c) {
    char digits[32];
    const auto end = std::to_chars(digits, digits + sizeof digits, v[c]).ptr;
    out += std::string(digits, end) + (c < 2 ? ", " : "]");
  }
  return out;
}

// Reads the points of the file `name` (the value of `node`, at `path`) into `out`: positions
// and, when the file has them, velocities. Reports what is wrong at the node.
bool readPointFile(Context& cx, const toml::node& node, const std::string& path,
                   const std::string& name, PointListShape& out) {
  const std::filesystem::path file = cx.directory() / name;
  const std::string shown = "\"" + file.string() + "\"";
  const auto fail = [&](const std::string& what, const std::string& expected = kPointFileText) {
    cx.error(cx.at(node), path, what + " (expected " + expected + ")");
    return false;
  };
  std::string extension = file.extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (extension != ".vdb" && extension != ".csv") {
    return fail(shown + " is neither a .vdb nor a .csv file");
  }
  std::error_code ec;
  if (!std::filesystem::exists(file, ec)) return fail("no such file " + shown);
  if (std::filesystem::is_directory(file, ec)) return fail(shown + " is a directory");
  FrameData points;
  bool hasVelocity = true;  // a CSV cache always has vx, vy, vz
  try {
    if (extension == ".vdb") {
      VdbCacheContents contents;
      points = readVdbPointCache(file, &contents);
      hasVelocity = contents.hasVelocity;
    } else {
      points = readCsvCache(file);
    }
  } catch (const std::exception& e) {
    return fail(shown + " cannot be read: " + e.what());
  }
  if (points.size() == 0) return fail(shown + " holds no points", kPointFileText + ", not empty");
  out.positions.resize(points.size());
  out.velocities.resize(hasVelocity ? points.size() : 0);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const auto row = static_cast<Eigen::Index>(i);
    const Eigen::Vector3f x(points.position[0][row], points.position[1][row],
                            points.position[2][row]);
    const Eigen::Vector3f v(points.velocity[0][row], points.velocity[1][row],
                            points.velocity[2][row]);
    const std::string which = shown + ": the point of id " + std::to_string(points.id[i]);
    const std::string expected = "points and velocities with every coordinate from -1e9 to 1e9";
    if (!(x.array().abs() <= kBig).all()) return fail(which + " is at " + vectorText(x), expected);
    if (hasVelocity && !(v.array().abs() <= kBig).all()) {
      return fail(which + " has the velocity " + vectorText(v), expected);
    }
    out.positions[i] = x;
    if (hasVelocity) out.velocities[i] = v;
  }
  return true;
}

}  // namespace

// A particle emitter whose particles are born at the points of a file, in turn (PointListShape).
void readFileEmitter(Context& cx, const toml::table& table, std::size_t index,
                     std::int64_t maxParticles, EmitterSettings& e) {
  TableReader r(cx, table, childPath("emitters", index));
  r.take("type");
  e.name = "file_" + std::to_string(index);
  r.string("name", e.name, "a name: a non-empty string, unique among the emitters");
  std::string name;
  const bool named = r.string("file", name, kPointFileText);
  if (table.get("file") == nullptr) r.missing("file", kPointFileText);
  r.vec3("position", e.position, kPositionText, Range{-kBig, kBig});
  readEmission(cx, table, r, maxParticles, e);
  PointListShape points;
  if (named && readPointFile(cx, *table.get("file"), r.pathOf("file"), name, points)) {
    if (!points.velocities.empty()) {
      // The file says how each particle starts: the emitter's velocity keys would be ignored.
      const std::string shown = "\"" + (cx.directory() / name).string() + "\"";
      for (const char* key : {"direction", "speed", "speed_jitter", "spread"}) {
        if (const toml::node* node = table.get(key)) {
          cx.error(cx.at(*node), r.pathOf(key),
                   "does not apply: " + shown +
                       " gives every point its velocity (expected direction, speed, "
                       "speed_jitter and spread only with a .vdb file without v)");
        }
      }
    }
    const auto count = static_cast<std::int64_t>(points.positions.size());
    if (table.get("rate") == nullptr && table.get("bursts") == nullptr) {
      // Neither rate nor bursts: one burst of every point at `start`.
      if (count > maxParticles) {
        cx.error(cx.at(*table.get("file")), r.pathOf("file"),
                 std::to_string(count) + " points are more than simulation.max_particles = " +
                     std::to_string(maxParticles) +
                     " (expected at most max_particles points for the burst of every point, or "
                     "a rate or bursts)");
      }
      e.bursts = {Burst{e.start, static_cast<std::uint64_t>(count)}};
    }
    e.shape = std::move(points);
  }
  r.finish(notForFileEmitter());
}

}  // namespace tickfx::io::detail
