// tickfx preview: an effect's frames, or a folder of caches, rendered to PNG without a DCC.
// The command runs in stages: its settings (app/PreviewSettings.h), the prepared preview (the
// input opened, the output folder made, the framing pass walked, cameras and flipbooks made),
// the frames rendered, then the report.
#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <future>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "app/Commands.h"
#include "app/PreviewSettings.h"
#include "app/PreviewSource.h"
#include "app/ProgressLine.h"
#include "app/preview/ColourBy.h"
#include "app/preview/FfmpegMovie.h"
#include "app/preview/FrameRenderer.h"
#include "app/preview/GifFlipbook.h"
#include "app/preview/PinholeCamera.h"
#include "app/preview/SceneGuides.h"
#include "io/cache/FrameCaches.h"
#include "io/util/AtomicFile.h"

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

// The contact sheet: every rendered frame (every stride-th past 64) in cells a quarter the size,
// four a row.
class ContactSheet {
 public:
  ContactSheet(std::int64_t rendered, ImageSize size) {
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

// ---- the prepared preview -----------------------------------------------------------------------

// The frames to render: A..B, every Nth from A.
struct FrameRange {
  std::int64_t first = 0, last = 0;
  long long every = 1;

  bool wants(std::int64_t f) const { return f >= first && f <= last && (f - first) % every == 0; }
};

// The input to render, how to colour it and which of its frames, ready to render: the output
// folder made, the framing pass walked, the cameras, guides and flipbooks made.
struct PreparedPreview {
  PreparedPreview(std::unique_ptr<PreviewSource> from, preview::ColourBy by, std::size_t keepBytes)
      : source(std::move(from)), colour(std::move(by)), kept(keepBytes) {}

  std::unique_ptr<PreviewSource> source;
  preview::ColourBy colour;
  FrameRange range;
  std::optional<OutputFolder> out;
  // The framing pass: the whole run's extent and the frames to render, counted and kept.
  RunExtent extent;
  std::int64_t rendered = 0;
  KeptFrames kept;
  std::optional<preview::PinholeCamera> camera, cellCamera;
  std::optional<ContactSheet> sheet;
  preview::RenderSettings render;
  bool legend = false;
  int textScale = 1;
  std::optional<preview::GifFlipbook> gif;
  std::optional<preview::FfmpegMovie> movie;

  const std::filesystem::path& outDir() const { return out->path(); }
};

// --color, or by default Cd when the frames have it, else speed.
preview::ColourBy chooseColour(const std::string& name, const PreviewSource& source) {
  try {
    const io::FrameData sample = source.sample();
    if (!name.empty()) return preview::ColourBy::parse(name, sample);
    const std::vector<std::string> choices = preview::ColourBy::choices(sample);
    const bool hasCd = std::find(choices.begin(), choices.end(), "Cd") != choices.end();
    return preview::ColourBy::parse(hasCd ? "Cd" : "speed", sample);
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("preview: --color: ") + e.what());
  }
}

// --frames and --every, within the source's frames.
FrameRange chooseFrames(const PreviewSettings& o, const PreviewSource& source, bool folder) {
  FrameRange range{source.frames().front(), source.frames().back(), o.every};
  if (o.frames) {
    const UsageError refused("preview: --frames: '" + *o.frames + "' is not a range A..B of this " +
                             (folder ? "folder's" : "effect's") + " frames (" +
                             std::to_string(range.first) + ".." + std::to_string(range.last) + ")");
    std::tie(range.first, range.last) = parseRange(*o.frames, range.first, range.last, refused);
  }
  return range;
}

// The input opened and checked, and the output folder made; nothing after printing why not (bad
// input: exit 2).
std::unique_ptr<PreparedPreview> openPreview(const PreviewSettings& o) {
  std::unique_ptr<PreviewSource> source = openPreviewSource(o.input, o.overrides);
  if (!source) return nullptr;
  const bool folder = std::filesystem::is_directory(o.input);
  if (folder && !o.overrides.empty()) {
    throw UsageError("preview: --set changes an effect file; " + o.input + " is a cache folder");
  }
  preview::ColourBy colour = chooseColour(o.colour, *source);
  auto p = std::make_unique<PreparedPreview>(std::move(source), std::move(colour), o.keepBytes);
  p->range = chooseFrames(o, *p->source, folder);
  try {
    p->out.emplace(o.out);
    io::requireWritable(io::cacheFilePath(o.out, p->range.first, "png"));
  } catch (const std::runtime_error& e) {  // WriteError too
    std::fprintf(stderr, "%s\n", e.what());
    if (p->out) p->out->abandon();
    return nullptr;
  }
  return p;
}

// The framing pass, then the cameras that see what it found (and the contact sheet's).
void frameRun(PreparedPreview& p, const PreviewSettings& o) {
  const FrameRange range = p.range;
  p.extent = scanRun(
      *p.source, p.colour, [range](std::int64_t f) { return range.wants(f); }, p.rendered, p.kept);
  const Eigen::Vector3d centre = 0.5 * (p.extent.lo + p.extent.hi);
  const auto cameraFor = [&](int width, int height) {
    return o.eye
               ? o.cameraAt(o.target.value_or(centre), width, height)
               : preview::PinholeCamera::framing(p.extent.lo, p.extent.hi, preview::upVector(o.up),
                                                 o.fov, width, height, kFramingMargin);
  };
  try {
    p.camera.emplace(cameraFor(o.size.width, o.size.height));
    if (o.sheet) {
      p.sheet.emplace(p.rendered, o.size);
      p.cellCamera.emplace(cameraFor(p.sheet->cellWidth(), p.sheet->cellHeight()));
    }
  } catch (const UsageError&) {
    p.out->abandon();
    throw;
  }
}

// The guides, the legend and the flipbooks.
void setUpRendering(PreparedPreview& p, const PreviewSettings& o) {
  p.render.background = kBackground;
  p.render.size = o.splatSize;
  if (o.guides) {
    p.render.grid = preview::GroundGrid::under(p.extent.lo, p.extent.hi, o.up);
    if (p.render.grid) p.render.axisLength = p.render.grid->spacing;
  }
  p.legend = o.guides && !p.colour.ownColours();
  p.textScale = o.size.width >= 640 ? 2 : 1;
  if (o.gif) {
    p.gif.emplace(o.size.width, o.size.height, preview::GifFlipbook::delayFor(p.source->fps()),
                  p.render.background);
  }
  if (o.ffmpeg) {
    p.movie.emplace(*o.ffmpeg, p.outDir() / "flipbook.mp4", o.size.width, o.size.height,
                    p.source->fps());
  }
}

// Everything before the first frame is rendered; nothing after printing why not (exit 2).
std::unique_ptr<PreparedPreview> preparePreview(const PreviewSettings& o) {
  std::unique_ptr<PreparedPreview> p = openPreview(o);
  if (!p) return nullptr;
  frameRun(*p, o);
  setUpRendering(*p, o);
  return p;
}

// ---- the frames ---------------------------------------------------------------------------------

// The second walk: each frame asked for rendered, captioned and written as PNG (and added to the
// flipbooks and the contact sheet). The previous frame's PNG (and flipbook frame) is encoded on a
// thread of its own while this one simulates and renders: one frame in flight, so files and
// flipbook frames keep their order.
class FrameRendering {
 public:
  explicit FrameRendering(PreparedPreview& p) : p_(p) {}

  // Renders every frame of the range; returns how many.
  std::int64_t run() {
    if (p_.kept.whole()) {
      for (const auto& [frame, lines] : p_.kept.frames()) renderOne(frame, lines);
    } else {
      const FrameRange range = p_.range;
      p_.source->walk(
          range.last, [range](std::int64_t f) { return range.wants(f); },
          [this](const io::FrameData& frame, const IdPairs& lines) { renderOne(frame, lines); });
    }
    if (encoding_.valid()) encoding_.get();
    progress_.finish();
    return written_;
  }

 private:
  preview::SplatImage render(const preview::PinholeCamera& view, const io::FrameData& frame,
                             const IdPairs& lines) const {
    return preview::renderFrame(view, frame,
                                p_.colour.colours(frame, p_.extent.valueLo, p_.extent.valueHi),
                                lines, p_.render);
  }

  void renderOne(const io::FrameData& frame, const IdPairs& lines) {
    const std::int64_t f = frame.frame;
    preview::SplatImage image = render(*p_.camera, frame, lines);
    preview::drawCaption(image, captionOf(*p_.source, frame, p_.render), p_.textScale);
    if (p_.legend) {
      preview::drawLegend(image, p_.colour.title(), p_.extent.valueLo, p_.extent.valueHi,
                          p_.textScale);
    }
    if (encoding_.valid()) encoding_.get();
    encoding_ = std::async(std::launch::async, [this, f, done = std::move(image)] {
      done.writePng(io::cacheFilePath(p_.outDir(), f, "png"));
      if (p_.gif) p_.gif->add(done);
      if (p_.movie) p_.movie->add(done);
    });
    if (p_.sheet && p_.sheet->takes(written_)) {
      preview::SplatImage cell = render(*p_.cellCamera, frame, lines);
      preview::drawCaption(cell, "frame " + std::to_string(f), 1);
      p_.sheet->place(written_, cell);
    }
    ++written_;
    progress_.update(written_, p_.rendered, io::cacheFilePath(p_.outDir(), f, "png").string());
  }

  PreparedPreview& p_;
  ProgressLine progress_{"frames"};
  std::int64_t written_ = 0;
  std::future<void> encoding_;
};

// ---- the report ---------------------------------------------------------------------------------

// The contact sheet and the flipbooks, written once every frame is. The exit code when the movie
// fails (reported), else nothing.
std::optional<int> finishFlipbooks(PreparedPreview& p) {
  if (p.sheet) p.sheet->image().writePng(p.outDir() / "sheet.png");
  if (p.gif) p.gif->write(p.outDir() / "flipbook.gif");
  if (p.movie) {
    try {
      p.movie->finish();
    } catch (const std::runtime_error& e) {
      std::fprintf(stderr, "%s\n", e.what());
      return kExitFailure;
    }
  }
  return std::nullopt;
}

void printPreviewSummary(const PreparedPreview& p, const PreviewSettings& o, std::int64_t written) {
  const std::filesystem::path& outDir = p.outDir();
  std::printf("%s: %" PRId64 " frames rendered to %s (%dx%d), frames %" PRId64 "..%" PRId64
              " every %lld\n",
              o.input.c_str(), written, outDir.string().c_str(), o.size.width, o.size.height,
              p.range.first, p.range.last, p.range.every);
  if (p.sheet) {
    std::printf("sheet: %s (%" PRId64 " frames, %dx%d cells)\n", (outDir / "sheet.png").c_str(),
                p.sheet->cells(), p.sheet->cellWidth(), p.sheet->cellHeight());
  }
  if (p.gif) {
    std::printf("flipbook: %s (%zu frames, %d/100 s each)\n", (outDir / "flipbook.gif").c_str(),
                p.gif->frameCount(), preview::GifFlipbook::delayFor(p.source->fps()));
  }
  if (p.movie) std::printf("movie: %s\n", (outDir / "flipbook.mp4").c_str());
}

}  // namespace

int previewCommand(Arguments& args) {
  if (args.flag("--help")) {
    std::fputs(kPreviewHelp, stdout);
    return kExitOk;
  }
  const PreviewSettings settings = readPreviewSettings(args);
  const std::unique_ptr<PreparedPreview> prepared = preparePreview(settings);
  if (!prepared) return kExitUsage;
  const std::int64_t written = FrameRendering(*prepared).run();
  if (const std::optional<int> failed = finishFlipbooks(*prepared)) return *failed;
  printPreviewSummary(*prepared, settings, written);
  return kExitOk;
}

}  // namespace tickfx::app
