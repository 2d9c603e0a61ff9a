// tickfx preview: an effect's frames, or a folder of caches, rendered to PNG without a DCC.
#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <future>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/Commands.h"
#include "app/PreviewSource.h"
#include "app/ProgressLine.h"
#include "io/util/AtomicFile.h"
#include "io/cache/FrameCaches.h"
#include "app/preview/ColourBy.h"
#include "app/preview/FfmpegMovie.h"
#include "app/preview/FrameRenderer.h"
#include "app/preview/GifFlipbook.h"
#include "app/preview/PinholeCamera.h"
#include "app/preview/SceneGuides.h"

namespace tickfx::app {
namespace {

const char* const kPreviewHelp =
    "usage: tickfx preview EFFECT.toml|CACHE_DIR [--out DIR] [--size WxH] [--frames A..B]\n"
    "                      [--every N] [--color speed|age|nage|id|ATTRIBUTE|Cd]\n"
    "                      [--point-size PIXELS | --radius METRES] [--camera X,Y,Z]\n"
    "                      [--lookat X,Y,Z] [--fov DEGREES] [--up y|z] [--no-guides]\n"
    "                      [--sheet] [--gif] [--mp4] [--keep-mb MB] [--set KEY=VALUE]...\n"
    "\n"
    "Renders frames to PNG (DIR/frame_0001.png, ...; default out/preview), each written whole or\n"
    "not at all: an effect run over its [output] length and frame rate, or the caches of a folder\n"
    "(frame_N.vdb, .ply or .csv, as tickfx run writes them). Unless --camera is given, the camera\n"
    "looks at the particles' bounds over the whole run from in front, above and to the right, "
    "with\n"
    "10 % of their size to spare on every side, so every particle of every frame is in the "
    "picture\n"
    "and the camera holds still. Particles are round splats, nearer over farther, coloured "
    "through\n"
    "viridis over the whole run's range (shown in a legend) or by their own Cd. A ground grid of\n"
    "1 m squares (coarser for effects wider than 100 m) and 1 m axis marks (x red, y green, z\n"
    "blue) show scale and up; a structure's springs are drawn as lines.\n"
    "  --size WxH         pixels (default 1280x720; 1 to 16384 a side)\n"
    "  --frames A..B      only frames A to B (default all)\n"
    "  --every N          every Nth frame from A (default 1)\n"
    "  --color C          speed (m/s), age (s), nage (age / life), id, life, mass, a custom\n"
    "                     attribute of the caches, or Cd (their own colours); by default Cd when\n"
    "                     the frames have it, else speed\n"
    "  --point-size P     splat diameter in pixels (default 3)\n"
    "  --radius R         splat radius in metres instead; a frame with pscale uses pscale\n"
    "  --camera X,Y,Z     the camera's position (metres), looking at the bounds' centre or at\n"
    "  --lookat X,Y,Z     this point\n"
    "  --fov DEGREES      vertical field of view (default 40)\n"
    "  --up y|z           the world's up axis (default y)\n"
    "  --no-guides        no grid, axis marks or legend\n"
    "  --sheet            also DIR/sheet.png: the frames rendered (at most 64, evenly picked) in "
    "a\n"
    "                     grid of cells a quarter the size, each labelled with its frame\n"
    "  --gif              also DIR/flipbook.gif: the frames rendered, looping\n"
    "  --mp4              also DIR/flipbook.mp4, through ffmpeg ($TICKFX_FFMPEG or ffmpeg on "
    "PATH;\n"
    "                     Debian: apt-get install ffmpeg)\n"
    "  --keep-mb MB       memory for the frames to render, kept from the framing pass (default\n"
    "                     1024; past it, or with 0, the effect runs again or the caches are read\n"
    "                     again: the same pictures)\n"
    "Each frame has the name, the frame, its time and the particle count in its top-left corner.\n"
    "Exit codes: 0 ok, 2 bad arguments or input (nothing written), 1 failure at run time.\n";

constexpr preview::Rgb kBackground{24, 24, 28};
constexpr std::int64_t kSheetCells = 64;
constexpr double kFramingMargin = 0.1;

struct Size {
  int width = 1280;
  int height = 720;
};

Size parseSize(const std::string& text) {
  const UsageError refused("preview: --size: '" + text +
                           "' is not WxH with whole numbers from 1 to " +
                           std::to_string(preview::SplatImage::kMaxSide));
  const std::size_t x = text.find('x');
  if (x == std::string::npos) throw refused;
  try {
    return {
        static_cast<int>(parseInteger(text.substr(0, x), "--size", 1, preview::SplatImage::kMaxSide)),
        static_cast<int>(parseInteger(text.substr(x + 1), "--size", 1, preview::SplatImage::kMaxSide))};
  } catch (const UsageError&) {
    throw refused;
  }
}

preview::UpAxis parseUp(const std::string& text) {
  if (text == "y") return preview::UpAxis::Y;
  if (text == "z") return preview::UpAxis::Z;
  throw UsageError("preview: --up: '" + text + "' (expected y or z)");
}

Eigen::Vector3d parsePoint(const std::string& option, const std::optional<std::string>& text) {
  try {
    const std::vector<double> v = parseNumberList(*text, option, 3, "x,y,z", -1e9, 1e9);
    return {v[0], v[1], v[2]};
  } catch (const UsageError&) {
    throw UsageError("preview: " + option + ": '" + *text +
                     "' is not a point X,Y,Z (metres, three numbers from -1e9 to 1e9)");
  }
}

// The particles' bounds and the colouring value's range over the whole run.
struct RunExtent {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  double valueLo = std::numeric_limits<double>::infinity();
  double valueHi = -valueLo;

  void add(const io::FrameData& frame, const std::vector<double>& values) {
    preview::growBounds(frame, lo, hi);
    for (std::size_t i = 0; i < values.size(); ++i) {
      // The range of the particles the camera frames.
      if (!std::isfinite(values[i]) || !preview::positionOf(frame, i).allFinite()) continue;
      valueLo = std::min(valueLo, values[i]);
      valueHi = std::max(valueHi, values[i]);
    }
  }
};

// The output folder: made before anything runs, and removed again when a later refusal leaves
// it empty, so that bad input writes nothing.
class OutputFolder {
 public:
  explicit OutputFolder(std::filesystem::path dir) : dir_(std::move(dir)) {
    std::error_code error;
    const bool existed = std::filesystem::exists(dir_, error);
    std::filesystem::create_directories(dir_, error);
    if (error) {
      throw std::runtime_error(dir_.string() + ": error: cannot make the output folder (" +
                               error.message() + ")");
    }
    made_ = !existed;
  }
  void abandon() const {
    std::error_code ignored;
    if (made_ && std::filesystem::is_empty(dir_, ignored)) std::filesystem::remove(dir_, ignored);
  }
  const std::filesystem::path& path() const { return dir_; }

 private:
  std::filesystem::path dir_;
  bool made_ = false;
};

// Everything the command line asks for, read and checked before anything runs.
struct PreviewOptions {
  std::string input;
  std::vector<std::string> overrides;
  std::filesystem::path out;
  Size size;
  std::string colour;
  std::optional<std::string> frames;
  long long every = 1;
  preview::SplatSize splatSize;
  std::optional<Eigen::Vector3d> eye, target;
  double fov = 40.0;
  preview::UpAxis up = preview::UpAxis::Y;
  bool guides = true;
  bool sheet = false;
  bool gif = false;
  std::optional<std::filesystem::path> ffmpeg;  // --mp4
  std::size_t keepBytes = std::size_t{1} << 30;

  // The camera at --camera looking at `look`; a camera that sees nothing is a usage error.
  preview::PinholeCamera cameraAt(const Eigen::Vector3d& look, int width, int height) const {
    try {
      return preview::PinholeCamera(*eye, look, preview::upVector(up), fov, width, height);
    } catch (const std::invalid_argument& e) {
      throw UsageError(std::string("preview: --camera: ") + e.what());
    }
  }
};

PreviewOptions readOptions(Arguments& args) {
  PreviewOptions o;
  o.overrides = args.values("--set");
  o.out = args.value("--out").value_or("out/preview");
  o.size = parseSize(args.value("--size").value_or("1280x720"));
  o.colour = args.value("--color").value_or("");  // empty: Cd when the frames have it, else speed
  o.frames = args.value("--frames");
  o.every = parseInteger(args.value("--every").value_or("1"), "preview: --every", 1, 1'000'000);
  const auto pointSize = args.value("--point-size");
  const auto radius = args.value("--radius");
  const auto eye = args.value("--camera");
  const auto lookat = args.value("--lookat");
  o.fov = parseNumber(args.value("--fov").value_or("40"), "preview: --fov", 1.0, 170.0);
  o.up = parseUp(args.value("--up").value_or("y"));
  o.guides = !args.flag("--no-guides");
  o.sheet = args.flag("--sheet");
  o.gif = args.flag("--gif");
  o.keepBytes = static_cast<std::size_t>(parseInteger(args.value("--keep-mb").value_or("1024"),
                                                      "preview: --keep-mb", 0, 1 << 20))
                << 20;
  const bool mp4 = args.flag("--mp4");
  o.input = args.positionals(1, "one effect file or cache folder: tickfx preview EFFECT.toml")[0];

  if (pointSize && radius) {
    throw UsageError("preview: --point-size and --radius each set the splat size: give one");
  }
  if (pointSize) {
    o.splatSize.diameterPixels =
        static_cast<double>(parseInteger(*pointSize, "preview: --point-size", 1, 100));
  }
  if (radius) o.splatSize.radiusMetres = parseNumber(*radius, "preview: --radius", 1e-6, 1e6);
  if (lookat && !eye) {
    throw UsageError("preview: --lookat needs --camera (without it the camera frames the run)");
  }
  if (eye) o.eye = parsePoint("--camera", eye);
  if (lookat) o.target = parsePoint("--lookat", lookat);
  if (o.eye && o.target) o.cameraAt(*o.target, o.size.width, o.size.height);
  if (mp4) {
    o.ffmpeg = preview::findFfmpeg();
    if (!o.ffmpeg) {
      throw UsageError(
          "preview: --mp4 needs ffmpeg, which is not installed (Debian: apt-get install ffmpeg; "
          "--gif needs nothing more)");
    }
  }
  return o;
}

// The contact sheet: every rendered frame (every stride-th past 64) in cells a quarter the size,
// four a row.
class ContactSheet {
 public:
  ContactSheet(std::int64_t rendered, Size size) {
    rendered = std::max<std::int64_t>(rendered, 1);
    stride_ = (rendered + kSheetCells - 1) / kSheetCells;
    cells_ = (rendered + stride_ - 1) / stride_;
    cellWidth_ = std::max(1, size.width / 4);
    cellHeight_ = std::max(1, size.height / 4);
    columns_ = static_cast<int>(std::min<std::int64_t>(4, cells_));
    const std::int64_t rows = (cells_ + columns_ - 1) / columns_;
    if (rows * cellHeight_ > preview::SplatImage::kMaxSide) {
      throw UsageError("preview: --sheet: " + std::to_string(cells_) +
                       " frames make a sheet too tall (use a smaller --size or a larger --every)");
    }
    image_.emplace(columns_ * cellWidth_, static_cast<int>(rows) * cellHeight_, kBackground);
  }

  // Whether the index-th rendered frame has a cell.
  bool takes(std::int64_t index) const { return index % stride_ == 0; }
  // Copies `cell` (cellWidth × cellHeight) into the index-th rendered frame's cell.
  void place(std::int64_t index, const preview::SplatImage& cell) {
    const std::int64_t at = index / stride_;
    const int x0 = static_cast<int>(at % columns_) * cellWidth_;
    const int y0 = static_cast<int>(at / columns_) * cellHeight_;
    for (int y = 0; y < cellHeight_; ++y) {
      for (int x = 0; x < cellWidth_; ++x) image_->set(x0 + x, y0 + y, cell.at(x, y));
    }
  }
  const preview::SplatImage& image() const { return *image_; }
  std::int64_t cells() const { return cells_; }
  int cellWidth() const { return cellWidth_; }
  int cellHeight() const { return cellHeight_; }

 private:
  std::int64_t stride_ = 1, cells_ = 1;
  int cellWidth_ = 1, cellHeight_ = 1, columns_ = 1;
  std::optional<preview::SplatImage> image_;
};

// The frames the first walk saw that the second renders, kept while they fit in the budget
// (--keep-mb), so that the second walk neither runs the effect again nor reads the caches again.
class KeptFrames {
 public:
  explicit KeptFrames(std::size_t budget) : budget_(budget) {}

  void keep(const io::FrameData& frame, const IdPairs& lines) {
    if (!whole_) return;
    bytes_ += frame.size() * (sizeof(std::uint64_t) + 12 * sizeof(float) +
                              frame.attributes.size() * sizeof(float)) +
              lines.size() * sizeof(IdPairs::value_type);
    if (bytes_ > budget_) {
      whole_ = false;
      frames_.clear();
      frames_.shrink_to_fit();
      return;
    }
    frames_.emplace_back(frame, lines);
  }
  // Whether every frame kept was kept: the second walk can take them from here.
  bool whole() const { return whole_; }
  const std::vector<std::pair<io::FrameData, IdPairs>>& frames() const { return frames_; }

 private:
  std::vector<std::pair<io::FrameData, IdPairs>> frames_;
  std::size_t budget_, bytes_ = 0;
  bool whole_ = true;
};

// The first walk: the whole run's extent (for a camera that holds still and one colour range),
// and the frames `wanted` takes, counted and kept where they fit.
RunExtent scanRun(PreviewSource& source, const preview::ColourBy& colour,
                  const std::function<bool(std::int64_t)>& wanted, std::int64_t& rendered,
                  KeptFrames& kept) {
  RunExtent extent;
  ProgressLine progress("frames (framing)");
  const auto total = static_cast<std::int64_t>(source.frames().size());
  std::int64_t done = 0;
  source.walk(
      source.frames().back(), [](std::int64_t) { return true; },
      [&](const io::FrameData& frame, const IdPairs& lines) {
        extent.add(frame, colour.values(frame));
        if (wanted(frame.frame)) {
          ++rendered;
          kept.keep(frame, lines);
        }
        ++done;
        progress.update(done, total, "");
      });
  if (!(extent.lo.x() <= extent.hi.x())) extent.lo = extent.hi = Eigen::Vector3d::Zero();
  if (!(extent.valueLo <= extent.valueHi)) extent.valueLo = extent.valueHi = 0.0;
  return extent;
}

// "NAME  frame F  t = T s  N particles  grid G m": what each frame says in its corner.
std::string captionOf(const PreviewSource& source, const io::FrameData& frame,
                      const preview::RenderSettings& settings) {
  char time[48] = "";
  if (source.knowsTimes()) std::snprintf(time, sizeof time, "  t = %.3f s", frame.timeSeconds);
  // The grid's spacing: the scale at a glance.
  char grid[48] = "";
  if (settings.grid) std::snprintf(grid, sizeof grid, "  grid %g m", settings.grid->spacing);
  char caption[320];
  std::snprintf(caption, sizeof caption, "%s  frame %" PRId64 "%s  %zu particles%s",
                source.name().c_str(), frame.frame, time, frame.size(), grid);
  return caption;
}

}  // namespace

int previewCommand(Arguments& args) {
  if (args.flag("--help")) {
    std::fputs(kPreviewHelp, stdout);
    return kExitOk;
  }
  const PreviewOptions options = readOptions(args);
  const std::unique_ptr<PreviewSource> source = openPreviewSource(options.input, options.overrides);
  if (!source) return kExitUsage;
  const bool folder = std::filesystem::is_directory(options.input);
  if (folder && !options.overrides.empty()) {
    throw UsageError("preview: --set changes an effect file; " + options.input +
                     " is a cache folder");
  }
  const preview::ColourBy colour = [&] {
    try {
      const io::FrameData sample = source->sample();
      if (!options.colour.empty()) return preview::ColourBy::parse(options.colour, sample);
      const std::vector<std::string> choices = preview::ColourBy::choices(sample);
      const bool hasCd = std::find(choices.begin(), choices.end(), "Cd") != choices.end();
      return preview::ColourBy::parse(hasCd ? "Cd" : "speed", sample);
    } catch (const std::invalid_argument& e) {
      throw UsageError(std::string("preview: --color: ") + e.what());
    }
  }();
  std::int64_t first = source->frames().front(), last = source->frames().back();
  if (options.frames) {
    const UsageError refused("preview: --frames: '" + *options.frames +
                             "' is not a range A..B of this " + (folder ? "folder's" : "effect's") +
                             " frames (" + std::to_string(first) + ".." + std::to_string(last) +
                             ")");
    std::tie(first, last) = parseRange(*options.frames, first, last, refused);
  }
  const long long every = options.every;
  const auto wanted = [&](std::int64_t f) {
    return f >= first && f <= last && (f - first) % every == 0;
  };
  const std::filesystem::path& outDir = options.out;
  const Size size = options.size;

  std::optional<OutputFolder> out;
  try {
    out.emplace(outDir);
    io::requireWritable(io::cacheFilePath(outDir, first, "png"));
  } catch (const std::runtime_error& e) {  // WriteError too
    std::fprintf(stderr, "%s\n", e.what());
    if (out) out->abandon();
    return kExitUsage;
  }

  std::int64_t rendered = 0;
  KeptFrames kept(options.keepBytes);
  const RunExtent extent = scanRun(*source, colour, wanted, rendered, kept);
  const Eigen::Vector3d centre = 0.5 * (extent.lo + extent.hi);
  const auto cameraFor = [&](int width, int height) {
    return options.eye ? options.cameraAt(options.target.value_or(centre), width, height)
                       : preview::PinholeCamera::framing(extent.lo, extent.hi, preview::upVector(options.up),
                                                    options.fov, width, height, kFramingMargin);
  };
  std::optional<preview::PinholeCamera> camera, cellCamera;
  std::optional<ContactSheet> sheet;
  try {
    camera.emplace(cameraFor(size.width, size.height));
    if (options.sheet) {
      sheet.emplace(rendered, size);
      cellCamera.emplace(cameraFor(sheet->cellWidth(), sheet->cellHeight()));
    }
  } catch (const UsageError&) {
    out->abandon();
    throw;
  }

  preview::RenderSettings settings;
  settings.background = kBackground;
  settings.size = options.splatSize;
  if (options.guides) {
    settings.grid = preview::GroundGrid::under(extent.lo, extent.hi, options.up);
    if (settings.grid) settings.axisLength = settings.grid->spacing;
  }
  const bool legend = options.guides && !colour.ownColours();
  const int textScale = size.width >= 640 ? 2 : 1;
  const auto render = [&](const preview::PinholeCamera& view, const io::FrameData& frame,
                          const IdPairs& lines) {
    return preview::renderFrame(view, frame, colour.colours(frame, extent.valueLo, extent.valueHi),
                           lines, settings);
  };
  std::optional<preview::GifFlipbook> gif;
  if (options.gif) {
    gif.emplace(size.width, size.height, preview::GifFlipbook::delayFor(source->fps()),
                settings.background);
  }
  std::optional<preview::FfmpegMovie> movie;
  if (options.ffmpeg) {
    movie.emplace(*options.ffmpeg, outDir / "flipbook.mp4", size.width, size.height, source->fps());
  }

  // Second walk: the frames asked for.
  ProgressLine progress("frames");
  std::int64_t written = 0;
  std::future<void> encoding;
  const auto renderOne = [&](const io::FrameData& frame, const IdPairs& lines) {
    const std::int64_t f = frame.frame;
    preview::SplatImage image = render(*camera, frame, lines);
    preview::drawCaption(image, captionOf(*source, frame, settings), textScale);
    if (legend) preview::drawLegend(image, colour.title(), extent.valueLo, extent.valueHi, textScale);
    // The previous frame's PNG (and flipbook frame) is encoded on a thread of its own while this
    // one simulates and renders: one frame in flight, so files and flipbook frames keep their
    // order.
    if (encoding.valid()) encoding.get();
    encoding = std::async(std::launch::async, [&, f, done = std::move(image)] {
      done.writePng(io::cacheFilePath(outDir, f, "png"));
      if (gif) gif->add(done);
      if (movie) movie->add(done);
    });
    if (sheet && sheet->takes(written)) {
      preview::SplatImage cell = render(*cellCamera, frame, lines);
      preview::drawCaption(cell, "frame " + std::to_string(f), 1);
      sheet->place(written, cell);
    }
    ++written;
    progress.update(written, rendered, io::cacheFilePath(outDir, f, "png").string());
  };
  if (kept.whole()) {
    for (const auto& [frame, lines] : kept.frames()) renderOne(frame, lines);
  } else {
    source->walk(last, wanted, renderOne);
  }
  if (encoding.valid()) encoding.get();
  progress.finish();
  if (sheet) sheet->image().writePng(outDir / "sheet.png");
  if (gif) gif->write(outDir / "flipbook.gif");
  if (movie) {
    try {
      movie->finish();
    } catch (const std::runtime_error& e) {
      std::fprintf(stderr, "%s\n", e.what());
      return kExitFailure;
    }
  }
  std::printf("%s: %" PRId64 " frames rendered to %s (%dx%d), frames %" PRId64 "..%" PRId64
              " every %lld\n",
              options.input.c_str(), written, outDir.string().c_str(), size.width, size.height,
              first, last, every);
  if (sheet) {
    std::printf("sheet: %s (%" PRId64 " frames, %dx%d cells)\n", (outDir / "sheet.png").c_str(),
                sheet->cells(), sheet->cellWidth(), sheet->cellHeight());
  }
  if (gif) {
    std::printf("flipbook: %s (%zu frames, %d/100 s each)\n", (outDir / "flipbook.gif").c_str(),
                gif->frameCount(), preview::GifFlipbook::delayFor(source->fps()));
  }
  if (movie) std::printf("movie: %s\n", (outDir / "flipbook.mp4").c_str());
  return kExitOk;
}

}  // namespace tickfx::app
