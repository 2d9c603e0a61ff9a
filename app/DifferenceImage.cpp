#include "app/DifferenceImage.h"

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "app/preview/ColourMap.h"
#include "app/preview/FrameRenderer.h"
#include "app/preview/PinholeCamera.h"
#include "app/preview/SceneGuides.h"

namespace tickfx::app {

preview::SplatImage renderDifference(const io::FrameData& a, const io::FrameData& b,
                                     const std::string& labelA, const std::string& labelB,
                                     std::int64_t tick, int width, int height,
                                     DifferenceSummary* summary) {
  // Each particle of a against its id in b (rows are in id order in both).
  constexpr double kMissing = std::numeric_limits<double>::infinity();
  std::vector<double> distance(a.size(), kMissing);
  DifferenceSummary found;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const auto it = std::lower_bound(b.id.begin(), b.id.end(), a.id[i]);
    if (it != b.id.end() && *it == a.id[i]) {
      const double d = (preview::positionOf(a, i) -
                        preview::positionOf(b, static_cast<std::size_t>(it - b.id.begin())))
                           .norm();
      distance[i] = std::isnan(d) ? kMissing : d;
      if (std::isfinite(distance[i])) found.largest = std::max(found.largest, d);
    }
    found.differing += distance[i] != 0.0 ? 1 : 0;
  }
  // Particles only b has are counted too; they are not drawn (a's state is the picture).
  for (const std::uint64_t id : b.id) {
    if (!std::binary_search(a.id.begin(), a.id.end(), id)) ++found.differing;
  }
  std::vector<preview::Rgb> colours(a.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    colours[i] = preview::viridis(!std::isfinite(distance[i]) ? 1.0
                                  : found.largest > 0.0       ? distance[i] / found.largest
                                                              : 0.0);
  }
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  preview::growBounds(a, lo, hi);
  preview::growBounds(b, lo, hi);
  if (!(lo.x() <= hi.x())) lo = hi = Eigen::Vector3d::Zero();
  const preview::PinholeCamera camera = preview::PinholeCamera::framing(
      lo, hi, preview::upVector(preview::UpAxis::Y), 40.0, width, height, 0.1);
  preview::RenderSettings settings;
  settings.grid = preview::GroundGrid::under(lo, hi, preview::UpAxis::Y);
  if (settings.grid) settings.axisLength = settings.grid->spacing;
  settings.size.diameterPixels = 4.0;
  preview::SplatImage image = preview::renderFrame(camera, a, colours, {}, settings);
  const int scale = width >= 640 ? 2 : 1;
  char caption[320];
  std::snprintf(caption, sizeof caption,
                "tick %" PRId64 "  t = %.4f s  %s against %s  %zu of %zu particles differ", tick,
                a.timeSeconds, labelA.c_str(), labelB.c_str(), found.differing,
                std::max(a.size(), b.size()));
  preview::drawCaption(image, caption, scale);
  preview::drawLegend(image, "distance (m)", 0.0, found.largest, scale);
  if (summary != nullptr) *summary = found;
  return image;
}

}  // namespace tickfx::app
