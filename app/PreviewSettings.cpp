#include "app/PreviewSettings.h"

#include <stdexcept>
#include <string>
#include <vector>

#include "app/preview/FfmpegMovie.h"
#include "app/preview/SplatImage.h"

namespace tickfx::app {
namespace {

ImageSize parseSize(const std::string& text) {
  const UsageError refused("preview: --size: '" + text +
                           "' is not WxH with whole numbers from 1 to " +
                           std::to_string(preview::SplatImage::kMaxSide));
  const std::size_t x = text.find('x');
  if (x == std::string::npos) throw refused;
  try {
    return {static_cast<int>(
                parseInteger(text.substr(0, x), "--size", 1, preview::SplatImage::kMaxSide)),
            static_cast<int>(
                parseInteger(text.substr(x + 1), "--size", 1, preview::SplatImage::kMaxSide))};
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

}  // namespace

preview::PinholeCamera PreviewSettings::cameraAt(const Eigen::Vector3d& look, int width,
                                                 int height) const {
  try {
    return preview::PinholeCamera(*eye, look, preview::upVector(up), fov, width, height);
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("preview: --camera: ") + e.what());
  }
}

PreviewSettings readPreviewSettings(Arguments& args) {
  PreviewSettings o;
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

}  // namespace tickfx::app
