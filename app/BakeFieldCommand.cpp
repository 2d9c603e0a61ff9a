// tickfx bake-field: an analytic vector field (uniform, vortex, shear, curl noise) baked into a
// .vdb file, or a sequence of them, so that samples and tests make their fields instead of
// shipping binaries.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "app/Commands.h"
#include "app/ProgressLine.h"
#include "io/effect/EditDistance.h"
#include "io/effect/VectorFieldSource.h"

namespace tickfx::app {
namespace {

constexpr const char* kBakeFieldHelp =
    "usage: tickfx bake-field KIND --out FILE.vdb [--voxel-size V] [--bounds x0,y0,z0,x1,y1,z1]\n"
    "                         [--grid NAME] [KIND's options] [--frames A..B --fps F]\n"
    "\n"
    "Bakes an analytic vector field into an OpenVDB file: one vec3s grid whose voxels with "
    "centres\n"
    "i*V inside the bounds are active and hold the field there, rounded to float once. The same\n"
    "fields as the `bake` table of a vector_field force (docs/effects.md). Units: metres, m/s.\n"
    "\n"
    "KIND and its options (defaults in brackets):\n"
    "  uniform      u = velocity\n"
    "                 --velocity X,Y,Z   m/s [1,0,0]\n"
    "  vortex       u = omega * axis x (x - centre), a rigid rotation\n"
    "                 --centre X,Y,Z     m [0,0,0]\n"
    "                 --axis X,Y,Z       direction, not all zero [0,1,0]\n"
    "                 --omega W          rad/s [1]\n"
    "  shear        u = rate * (gradient . (x - origin)) * direction\n"
    "                 --origin X,Y,Z     m [0,0,0]\n"
    "                 --direction X,Y,Z  the flow, not all zero [1,0,0]\n"
    "                 --gradient X,Y,Z   the way the speed grows, not all zero [0,1,0]\n"
    "                 --rate R           1/s [1]\n"
    "  curl-noise   divergence-free noise, a pure function of the seed\n"
    "                 --seed N           0 to 9223372036854775807 [0]\n"
    "                 --frequency F      rad/m, > 0 [3]\n"
    "                 --amplitude A      m/s, the order of |u| [1]\n"
    "                 --octaves N        1 to 16 [4]\n"
    "                 --evolution W      rad/s: how fast the noise changes in time [0]\n"
    "Grid:\n"
    "  --out FILE.vdb       the file written (required); replaced whole, never left half-written\n"
    "  --voxel-size V       metres [0.1]\n"
    "  --bounds x0,y0,z0,x1,y1,z1  the baked box in metres [-1,-1,-1,1,1,1]\n"
    "  --grid NAME          the grid's name [vel]\n"
    "  --staggered          a staggered (MAC) grid: component c at the centre of the voxel's\n"
    "                       face on the -c side\n"
    "  --background X,Y,Z   the value outside the baked voxels [0,0,0]\n"
    "Sequences (curl noise with --evolution changes in time):\n"
    "  --frames A..B        bake frames A to B, frame f at time (f - A)/F s, each into --out with\n"
    "                       {frame} replaced by f zero-padded to --frame-padding digits [4]\n"
    "  --fps F              the sequence's frames per second (required with --frames)\n"
    "At most 100000000 voxels over all frames. Exit codes: 0 ok, 2 usage errors (nothing is\n"
    "written), 1 failure at run time.\n";

constexpr double kBig = 1e9;
constexpr long long kMaxFrame = io::kMaxFieldFrameNumber;
constexpr long long kMaxFrames = io::kMaxFieldFrames;

const std::vector<std::pair<std::string, std::vector<std::string>>>& kindOptions() {
  static const std::vector<std::pair<std::string, std::vector<std::string>>> options = {
      {"uniform", {"--velocity"}},
      {"vortex", {"--centre", "--axis", "--omega"}},
      {"shear", {"--origin", "--direction", "--gradient", "--rate"}},
      {"curl-noise", {"--seed", "--frequency", "--amplitude", "--octaves", "--evolution"}}};
  return options;
}

// "x,y,z" (or `count` numbers), each a number in [-1e9, 1e9].
Eigen::Vector3d parseVector(const std::string& text, const std::string& option,
                            bool nonZero = false) {
  const std::vector<double> v = parseNumberList(text, option, 3, "x,y,z", -kBig, kBig);
  const Eigen::Vector3d out(v[0], v[1], v[2]);
  if (nonZero && out.isZero(0.0)) {
    throw UsageError(option + ": '" + text + "' is not a direction (expected x,y,z not all zero)");
  }
  return out;
}

// A number in (0, max]: a size or a rate.
double parsePositive(const std::string& text, const std::string& option, double max) {
  char range[64];
  std::snprintf(range, sizeof range, "(0, %g]", max);
  const UsageError refused(option + ": '" + text + "' is not a number in " + range);
  double v = 0.0;
  try {
    v = parseNumber(text, option, 0.0, max);
  } catch (const UsageError&) {
    throw refused;
  }
  if (!(v > 0.0)) throw refused;
  return v;
}

// "A..B" with whole numbers A <= B.
std::pair<int, int> parseFrames(const std::string& text) {
  const std::string expected = "bake-field: --frames: '" + text +
                               "' is not a frame range A..B (whole numbers from -1000000 to "
                               "1000000, A <= B)";
  const auto [a, b] = parseRange(text, -kMaxFrame, kMaxFrame, UsageError(expected));
  if (b - a + 1 > kMaxFrames) {
    throw UsageError("bake-field: --frames: " + std::to_string(b - a + 1) +
                     " frames are too many (expected at most 10000)");
  }
  return {static_cast<int>(a), static_cast<int>(b)};
}

std::string numberText(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.10g", v);
  return buffer;
}

// ---- settings -------------------------------------------------------------------------------

// The command line as given: every option read (in a fixed order: a value may look like an
// option), nothing checked yet.
struct BakeArguments {
  std::optional<std::string> out, voxelSize, bounds, grid, background, frames, fps, padding;
  bool staggered = false;
  std::map<std::string, std::string> given;  // the kinds' options, by name
  std::string kind;
};

BakeArguments readBakeArguments(Arguments& args) {
  BakeArguments a;
  a.out = args.value("--out");
  a.voxelSize = args.value("--voxel-size");
  a.bounds = args.value("--bounds");
  a.grid = args.value("--grid");
  a.staggered = args.flag("--staggered");
  a.background = args.value("--background");
  a.frames = args.value("--frames");
  a.fps = args.value("--fps");
  a.padding = args.value("--frame-padding");
  for (const auto& [kind, options] : kindOptions()) {
    for (const std::string& option : options) {
      if (const auto v = args.value(option)) a.given[option] = *v;
    }
  }
  a.kind = args.positionals(1,
                            "a field kind: tickfx bake-field KIND --out FILE.vdb (KIND: uniform, "
                            "vortex, shear or curl-noise)")[0];
  return a;
}

// The kind's index in kindOptions(); UsageError for an unknown kind or another kind's option.
std::size_t checkKind(const BakeArguments& a) {
  std::vector<std::string> kinds;
  std::optional<std::size_t> index;
  for (const auto& [name, options] : kindOptions()) {
    if (name == a.kind) index = kinds.size();
    kinds.push_back(name);
  }
  if (!index) {
    const std::optional<std::string> guess = io::closestMatch(a.kind, kinds);
    throw UsageError("bake-field: unknown kind '" + a.kind + "' " +
                     (guess ? "(did you mean '" + *guess + "'?)"
                            : "(expected " + joinWords(kinds, " or ") + ")"));
  }
  const std::vector<std::string>& own = kindOptions()[*index].second;
  for (const auto& [option, value] : a.given) {
    if (std::find(own.begin(), own.end(), option) == own.end()) {
      throw UsageError("bake-field: " + option + " does not apply to kind '" + a.kind +
                       "' (its options: " + joinWords(own, " and ") + ")");
    }
  }
  return *index;
}

const std::string kBakePrefix = "bake-field: ";

// The kind's own options, onto `bake`'s defaults.
void readKindOptions(const std::map<std::string, std::string>& given, io::FieldBakeSettings& bake) {
  const auto option = [&](const char* name) -> std::optional<std::string> {
    const auto it = given.find(name);
    if (it == given.end()) return std::nullopt;
    return it->second;
  };
  const std::string& p = kBakePrefix;
  if (const auto v = option("--velocity")) bake.velocity = parseVector(*v, p + "--velocity");
  if (const auto v = option("--centre")) bake.centre = parseVector(*v, p + "--centre");
  if (const auto v = option("--axis")) bake.axis = parseVector(*v, p + "--axis", true);
  if (const auto v = option("--omega")) bake.omega = parseNumber(*v, p + "--omega", -kBig, kBig);
  if (const auto v = option("--origin")) bake.origin = parseVector(*v, p + "--origin");
  if (const auto v = option("--direction")) {
    bake.direction = parseVector(*v, p + "--direction", true);
  }
  if (const auto v = option("--gradient")) bake.gradient = parseVector(*v, p + "--gradient", true);
  if (const auto v = option("--rate")) bake.rate = parseNumber(*v, p + "--rate", -kBig, kBig);
  if (const auto v = option("--seed")) {
    bake.seed = static_cast<std::uint64_t>(parseInteger(*v, p + "--seed", 0, INT64_MAX));
  }
  if (const auto v = option("--frequency")) {
    bake.frequency = parsePositive(*v, p + "--frequency", kBig);
  }
  if (const auto v = option("--amplitude")) {
    bake.amplitude = parseNumber(*v, p + "--amplitude", 0.0, kBig);
  }
  if (const auto v = option("--octaves")) {
    bake.octaves = static_cast<int>(parseInteger(*v, p + "--octaves", 1, io::kMaxCurlOctaves));
  }
  if (const auto v = option("--evolution")) {
    bake.evolution = parseNumber(*v, p + "--evolution", 0.0, kBig);
  }
}

// --bounds: x0,y0,z0,x1,y1,z1 with x0 <= x1, y0 <= y1 and z0 <= z1.
void readBounds(const std::string& text, io::FieldBakeSettings& bake) {
  const std::string& p = kBakePrefix;
  const std::vector<double> b =
      parseNumberList(text, p + "--bounds", 6, "x0,y0,z0,x1,y1,z1", -kBig, kBig);
  for (int c = 0; c < 3; ++c) {
    if (b[c + 3] < b[c]) {
      const std::string axis(1, "xyz"[c]);
      throw UsageError(p + "--bounds: " + axis + "1 = " + numberText(b[c + 3]) + " is below " +
                       axis + "0 = " + numberText(b[c]) +
                       " (expected x0,y0,z0,x1,y1,z1 with x0 <= x1, y0 <= y1 and z0 <= z1)");
    }
  }
  bake.min = Eigen::Vector3d(b[0], b[1], b[2]);
  bake.max = Eigen::Vector3d(b[3], b[4], b[5]);
}

// The frames baked: one file, or a sequence of them.
struct BakeSequence {
  bool sequence = false;  // --frames: --out is a pattern with {frame}
  int first = 0, last = 0, digits = 4;
  double rate = 0.0;  // frames per second

  int count() const { return last - first + 1; }
};

BakeSequence readSequence(const BakeArguments& a) {
  const std::string& p = kBakePrefix;
  if (a.frames && !a.fps)
    throw UsageError(p + "--frames needs --fps (the sequence's frames per second)");
  if (a.fps && !a.frames) throw UsageError(p + "--fps needs --frames A..B");
  if (a.padding && !a.frames) throw UsageError(p + "--frame-padding needs --frames A..B");
  BakeSequence s;
  if (a.frames) {
    s.sequence = true;
    std::tie(s.first, s.last) = parseFrames(*a.frames);
    s.rate = parsePositive(*a.fps, p + "--fps", 1e6);
    if (a.padding)
      s.digits = static_cast<int>(parseInteger(*a.padding, p + "--frame-padding", 1, 10));
  }
  const bool pattern = a.out->find("{frame}") != std::string::npos;
  if (a.frames && !pattern) {
    throw UsageError(p + "--out: '" + *a.out +
                     "' has no {frame} (expected a pattern such as vel.{frame}.vdb with --frames)");
  }
  if (!a.frames && pattern) {
    throw UsageError(p + "--out: '" + *a.out + "' has {frame} but no --frames A..B is given");
  }
  return s;
}

// Everything `tickfx bake-field` is asked for, checked before anything is written.
struct BakeFieldSettings {
  std::string kind;
  std::string out;  // a file, or with a sequence a pattern with {frame}
  io::FieldBakeSettings bake;
  std::string gridName;
  BakeSequence frames;
};

BakeFieldSettings readBakeFieldSettings(Arguments& args) {
  const BakeArguments a = readBakeArguments(args);
  const std::size_t kind = checkKind(a);
  if (!a.out || a.out->empty()) throw UsageError("bake-field: --out FILE.vdb is required");
  BakeFieldSettings s;
  s.kind = a.kind;
  s.out = *a.out;
  s.bake.kind = static_cast<io::FieldBakeSettings::Kind>(kind);
  readKindOptions(a.given, s.bake);
  const std::string& p = kBakePrefix;
  if (a.voxelSize) s.bake.voxelSize = parsePositive(*a.voxelSize, p + "--voxel-size", kBig);
  if (a.bounds) readBounds(*a.bounds, s.bake);
  s.bake.staggered = a.staggered;
  if (a.background) s.bake.background = parseVector(*a.background, p + "--background");
  s.gridName = a.grid.value_or("vel");
  if (s.gridName.empty()) throw UsageError(p + "--grid: the grid needs a name");
  s.frames = readSequence(a);
  return s;
}

// The grid's voxels a frame, judged as an effect's bake table is; UsageError when too many.
double checkBakeSize(const BakeFieldSettings& s) {
  const std::string& p = kBakePrefix;
  const double h = s.bake.voxelSize;
  const int count = s.frames.count();
  const io::BakeSize size = io::measureBake(s.bake, count);
  switch (size.problem) {
    case io::BakeSize::Problem::None:
      break;
    case io::BakeSize::Problem::IndexReach:
      throw UsageError(p + "--voxel-size: " + numberText(h) + " m puts the bounds " +
                       numberText(size.reachVoxels) +
                       " voxels from the origin (expected at least " +
                       numberText(size.minVoxelSize) + " m for these bounds)");
    case io::BakeSize::Problem::EmptyBox:
      throw UsageError(p + "--bounds: the box holds no voxel centre at --voxel-size " +
                       numberText(h) + " (expected at least one point i*V on each axis)");
    case io::BakeSize::Problem::TooManyVoxels:
      throw UsageError(p + "--voxel-size " + numberText(h) + " and --bounds make " +
                       numberText(size.perFrame) + " voxels a frame, " + numberText(size.total) +
                       " over " + std::to_string(count) + (count == 1 ? " frame" : " frames") +
                       " (expected at most 100000000)");
  }
  return size.perFrame;
}

// ---- baking ---------------------------------------------------------------------------------

// Bakes every frame into its file, a line for each.
void bakeFrames(const BakeFieldSettings& s, double perFrame) {
  const BakeSequence& frames = s.frames;
  const AnalyticField field = io::analyticField(s.bake);
  const BakeSettings settings = io::bakeSettings(s.bake, s.gridName);
  const std::filesystem::path parent = std::filesystem::path(s.out).parent_path();
  if (!parent.empty()) std::filesystem::create_directories(parent);
  ProgressLine progress("frames");
  for (int f = frames.first; f <= frames.last; ++f) {
    const std::string path = frames.sequence ? sequenceFramePath(s.out, f, frames.digits) : s.out;
    const double time = frames.sequence ? (f - frames.first) / frames.rate : 0.0;
    progress.update(f - frames.first, frames.count(), path);
    bakeField(field, settings, path, time);
    progress.finish();  // the line below replaces it
    std::printf("%s: %s field, grid '%s', %.0f voxels of %s m%s\n", path.c_str(), s.kind.c_str(),
                s.gridName.c_str(), perFrame, numberText(s.bake.voxelSize).c_str(),
                frames.sequence ? (", t = " + numberText(time) + " s").c_str() : "");
  }
}

}  // namespace

int bakeFieldCommand(Arguments& args) {
  if (args.flag("--help")) {
    std::fputs(kBakeFieldHelp, stdout);
    return kExitOk;
  }
  // Everything is checked before anything is written.
  const BakeFieldSettings settings = readBakeFieldSettings(args);
  const double perFrame = checkBakeSize(settings);
  bakeFrames(settings, perFrame);
  return kExitOk;
}

}  // namespace tickfx::app
