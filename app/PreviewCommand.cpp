// tickfx preview: an effect's frames rendered to PNG, without a DCC.
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "app/Commands.h"
#include "app/ProgressLine.h"
#include "io/AtomicFile.h"
#include "io/FrameTimes.h"
#include "io/cache/FrameCaches.h"
#include "io/effect/EffectBuilder.h"
#include "io/effect/EffectLoader.h"
#include "io/preview/ColourMap.h"
#include "io/preview/PinholeCamera.h"
#include "io/preview/PixelFont.h"
#include "io/preview/SplatImage.h"

namespace tickfx::app {
namespace {

const char* const kPreviewHelp =
    "usage: tickfx preview EFFECT.toml [--out DIR] [--size WxH] [--frames A..B] [--every N]\n"
    "                      [--color speed|age|id] [--point-size PIXELS] [--sheet]\n"
    "                      [--set KEY=VALUE]...\n"
    "\n"
    "Runs the effect over its [output] length and frame rate and renders frames to PNG\n"
    "(DIR/frame_0001.png, ...; default out/preview), each written whole or not at all. The camera\n"
    "looks at the particles' bounds over the whole run, from in front, above and to the right,\n"
    "with 10 % to spare, so every particle of every frame is in the picture and the camera holds\n"
    "still. Particles are round splats, nearer over farther, coloured through viridis by speed\n"
    "(m/s, the default), age (s) or id, over the range of the whole run.\n"
    "  --size WxH         pixels (default 1280x720; 1 to 16384 a side)\n"
    "  --frames A..B      only frames A to B (1-based; default all)\n"
    "  --every N          every Nth frame from A (default 1)\n"
    "  --point-size P     splat diameter in pixels (default 3)\n"
    "  --sheet            also DIR/sheet.png: the frames rendered (at most 64, evenly picked) in "
    "a\n"
    "                     grid of cells a quarter the size, each labelled with its frame\n"
    "Each frame has the effect's name, the frame, its time and the particle count in a corner.\n"
    "Exit codes: 0 ok, 2 bad arguments or effect (nothing written), 1 failure at run time.\n";

struct Size {
  int width = 1280;
  int height = 720;
};

Size parseSize(const std::string& text) {
  const UsageError refused("preview: --size: '" + text +
                           "' is not WxH with whole numbers from 1 to " +
                           std::to_string(io::SplatImage::kMaxSide));
  const std::size_t x = text.find('x');
  if (x == std::string::npos) throw refused;
  try {
    return {
        static_cast<int>(parseInteger(text.substr(0, x), "--size", 1, io::SplatImage::kMaxSide)),
        static_cast<int>(parseInteger(text.substr(x + 1), "--size", 1, io::SplatImage::kMaxSide))};
  } catch (const UsageError&) {
    throw refused;
  }
}

enum class Colouring { Speed, Age, Id };

Colouring parseColouring(const std::string& name) {
  if (name == "speed") return Colouring::Speed;
  if (name == "age") return Colouring::Age;
  if (name == "id") return Colouring::Id;
  throw UsageError("preview: --color: '" + name + "' (expected " +
                   joinWords({"speed", "age", "id"}, " or ") + ")");
}

// One frame's particles: positions, and the value each is coloured by.
struct FrameState {
  Vec3Column positions;
  std::vector<double> values;
};

FrameState capture(const ParticleSystem& system, Colouring colouring) {
  FrameState s;
  system.renderPositions(s.positions);
  const std::size_t n = system.pool().size();
  s.values.resize(n);
  if (colouring == Colouring::Speed) {
    Vec3Column v;
    system.renderVelocities(v);
    for (std::size_t i = 0; i < n; ++i) {
      const auto r = static_cast<Eigen::Index>(i);
      s.values[i] =
          std::sqrt(double(v.x[r]) * v.x[r] + double(v.y[r]) * v.y[r] + double(v.z[r]) * v.z[r]);
    }
  } else if (colouring == Colouring::Age) {
    FloatColumn a;
    system.renderAges(a);
    for (std::size_t i = 0; i < n; ++i) s.values[i] = a[static_cast<Eigen::Index>(i)];
  } else {
    for (std::size_t i = 0; i < n; ++i) {
      s.values[i] = static_cast<double>(system.pool().id()[static_cast<Eigen::Index>(i)]);
    }
  }
  return s;
}

// What the camera and the colour map need from the whole run: the particles' bounds and the
// range of the colouring value.
struct RunExtent {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  double valueLo = std::numeric_limits<double>::infinity();
  double valueHi = -valueLo;

  void add(const FrameState& s) {
    for (Eigen::Index i = 0; i < s.positions.x.size(); ++i) {
      const Eigen::Vector3d p(s.positions.x[i], s.positions.y[i], s.positions.z[i]);
      if (!p.allFinite()) continue;
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
      valueLo = std::min(valueLo, s.values[static_cast<std::size_t>(i)]);
      valueHi = std::max(valueHi, s.values[static_cast<std::size_t>(i)]);
    }
  }
  bool empty() const { return !(lo.x() <= hi.x()); }
};

constexpr io::Rgb kBackground{24, 24, 28};
constexpr std::int64_t kSheetCells = 64;

// Burns `text` into the image's top-left corner, light on a dark box.
void burnLabel(io::SplatImage& image, const std::string& text, int scale) {
  const int pad = 2 * scale;
  io::fillRect(image, 0, 0, io::textWidth(text, scale) + 2 * pad,
               io::kGlyphHeight * scale + 2 * pad, {0, 0, 0});
  io::drawText(image, pad, pad, text, {235, 235, 235}, scale);
}

// Named as the caches of `tickfx run` are: frame_0001.png beside frame_0001.csv.
std::filesystem::path framePath(const std::filesystem::path& dir, std::int64_t frame) {
  return io::cacheFilePath(dir, frame, "png");
}

}  // namespace

int previewCommand(Arguments& args) {
  if (args.flag("--help")) {
    std::fputs(kPreviewHelp, stdout);
    return kExitOk;
  }
  const std::vector<std::string> overrides = args.values("--set");
  const std::filesystem::path out = args.value("--out").value_or("out/preview");
  const Size size = parseSize(args.value("--size").value_or("1280x720"));
  const Colouring colouring = parseColouring(args.value("--color").value_or("speed"));
  const auto framesOption = args.value("--frames");
  const long long every =
      parseInteger(args.value("--every").value_or("1"), "preview: --every", 1, 1'000'000);
  const long long pointSize =
      parseInteger(args.value("--point-size").value_or("3"), "preview: --point-size", 1, 100);
  const bool wantSheet = args.flag("--sheet");
  const std::string effectPath =
      args.positionals(1, "one effect file: tickfx preview EFFECT.toml")[0];

  const io::LoadResult load = io::loadEffectFile(effectPath, overrides);
  for (const io::Diagnostic& d : load.diagnostics) std::fprintf(stderr, "%s\n", d.format().c_str());
  if (!load.ok()) return kExitUsage;
  const io::EffectSettings& effect = *load.effect;
  const std::int64_t count = effect.output.frameCount();
  std::int64_t first = 1, last = count;
  if (framesOption) {
    const std::string range = "preview: --frames: '" + *framesOption +
                              "' is not a range A..B of this effect's frames (1.." +
                              std::to_string(count) + ")";
    const std::size_t dots = framesOption->find("..");
    if (dots == std::string::npos) throw UsageError(range);
    try {
      first = parseInteger(framesOption->substr(0, dots), "--frames", 1, count);
      last = parseInteger(framesOption->substr(dots + 2), "--frames", first, count);
    } catch (const UsageError&) {
      throw UsageError(range);
    }
  }
  const Flicks length = io::lengthOfFrames(effect.output.fps, count, "output length");

  // Building loads the effect's fields: a file that does not load is bad input.
  std::unique_ptr<ParticleSystem> system;
  try {
    system = io::buildOfflineSystem(effect, std::nullopt);
  } catch (const io::BuildError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return kExitUsage;
  }
  // The output folder takes files before anything runs.
  try {
    std::error_code error;
    std::filesystem::create_directories(out, error);
    if (error) {
      std::fprintf(stderr, "%s: error: cannot make the output folder (%s)\n", out.c_str(),
                   error.message().c_str());
      return kExitUsage;
    }
    io::requireWritable(framePath(out, first));
  } catch (const io::WriteError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return kExitUsage;
  }

  // First pass: the whole run's extent, for a camera that holds still and one colour range.
  RunExtent extent;
  {
    io::FrameSchedule schedule = io::FrameSchedule::fixedRate(effect.output.fps, length);
    ProgressLine progress("frames (framing)");
    while (const std::optional<Flicks> d = schedule.next()) {
      system->advance(*d);
      extent.add(capture(*system, colouring));
      progress.update(schedule.framesDone(), count,
                      static_cast<double>(schedule.framesDone()) / static_cast<double>(count), "");
    }
  }
  if (extent.empty()) extent.lo = extent.hi = Eigen::Vector3d::Zero();
  const io::PinholeCamera camera = io::PinholeCamera::framing(
      extent.lo, extent.hi, Eigen::Vector3d::UnitY(), 40.0, size.width, size.height);
  const double span = extent.valueHi > extent.valueLo ? extent.valueHi - extent.valueLo : 1.0;

  // Second pass: the same ticks again (the state at a frame is a pure function of the effect),
  // rendering the frames asked for.
  const std::string name = std::filesystem::path(effectPath).stem().string();
  const auto render = [&](const io::PinholeCamera& view, const FrameState& state, float radius) {
    std::vector<io::Splat> splats;
    splats.reserve(state.values.size());
    for (std::size_t i = 0; i < state.values.size(); ++i) {
      const auto r = static_cast<Eigen::Index>(i);
      const auto q = view.project(
          Eigen::Vector3d(state.positions.x[r], state.positions.y[r], state.positions.z[r]));
      if (!q) continue;
      splats.push_back({static_cast<float>(q->x), static_cast<float>(q->y),
                        static_cast<float>(q->depth), radius,
                        io::viridis((state.values[i] - extent.valueLo) / span)});
    }
    io::SplatImage image(view.width(), view.height(), kBackground);
    image.draw(std::move(splats));
    return image;
  };
  // The sheet: every rendered frame (every sheetStride-th past 64), in cells a quarter the size.
  const std::int64_t rendered = (last - first) / every + 1;
  const std::int64_t sheetStride = (rendered + kSheetCells - 1) / kSheetCells;
  const std::int64_t cells = (rendered + sheetStride - 1) / sheetStride;
  const int cellWidth = std::max(1, size.width / 4), cellHeight = std::max(1, size.height / 4);
  const int columns = static_cast<int>(std::min<std::int64_t>(4, cells));
  const int rows = static_cast<int>((cells + columns - 1) / columns);
  std::optional<io::SplatImage> sheet;
  std::optional<io::PinholeCamera> cellCamera;
  if (wantSheet) {
    if (static_cast<std::int64_t>(rows) * cellHeight > io::SplatImage::kMaxSide) {
      throw UsageError("preview: --sheet: " + std::to_string(cells) +
                       " frames make a sheet too tall (use a smaller --size or a larger --every)");
    }
    sheet.emplace(columns * cellWidth, rows * cellHeight, kBackground);
    cellCamera.emplace(io::PinholeCamera::framing(extent.lo, extent.hi, Eigen::Vector3d::UnitY(),
                                                  40.0, cellWidth, cellHeight));
  }
  system = io::buildOfflineSystem(effect, std::nullopt);
  io::FrameSchedule schedule = io::FrameSchedule::fixedRate(effect.output.fps, length);
  ProgressLine progress("frames");
  std::int64_t written = 0;
  while (const std::optional<Flicks> d = schedule.next()) {
    system->advance(*d);
    const std::int64_t f = schedule.framesDone();
    if (f > last) break;
    if (f < first || (f - first) % every != 0) continue;
    const FrameState state = capture(*system, colouring);
    io::SplatImage image = render(camera, state, 0.5f * static_cast<float>(pointSize));
    char label[160];
    std::snprintf(label, sizeof label, "%s  frame %" PRId64 "  t = %.3f s  %zu particles",
                  name.c_str(), f, system->shownSeconds(), state.values.size());
    burnLabel(image, label, size.width >= 640 ? 2 : 1);
    image.writePng(framePath(out, f));
    const std::int64_t index = (f - first) / every;
    if (sheet && index % sheetStride == 0) {
      const std::int64_t cell = index / sheetStride;
      io::SplatImage small = render(*cellCamera, state, 0.5f * static_cast<float>(pointSize));
      burnLabel(small, "frame " + std::to_string(f), 1);
      const int x0 = static_cast<int>(cell % columns) * cellWidth;
      const int y0 = static_cast<int>(cell / columns) * cellHeight;
      for (int y = 0; y < cellHeight; ++y) {
        for (int x = 0; x < cellWidth; ++x) sheet->set(x0 + x, y0 + y, small.at(x, y));
      }
    }
    ++written;
    progress.update(f - first + 1, last - first + 1,
                    static_cast<double>(f - first + 1) / static_cast<double>(last - first + 1),
                    framePath(out, f).string());
  }
  if (sheet) sheet->writePng(out / "sheet.png");
  progress.finish();
  std::printf("%s: %" PRId64 " frames rendered to %s (%dx%d), frames %" PRId64 "..%" PRId64
              " every %lld\n",
              effectPath.c_str(), written, out.string().c_str(), size.width, size.height, first,
              last, every);
  if (sheet) {
    std::printf("sheet: %s (%" PRId64 " frames, %dx%d cells)\n", (out / "sheet.png").c_str(), cells,
                cellWidth, cellHeight);
  }
  return kExitOk;
}

}  // namespace tickfx::app
