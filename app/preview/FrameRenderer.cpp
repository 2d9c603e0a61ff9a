#include "app/preview/FrameRenderer.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace tickfx::preview {
namespace {

// The row of `id` in a frame whose rows are in id order, or nothing.
std::optional<std::size_t> rowOf(const io::FrameData& frame, std::uint64_t id) {
  const auto it = std::lower_bound(frame.id.begin(), frame.id.end(), id);
  if (it == frame.id.end() || *it != id) return std::nullopt;
  return static_cast<std::size_t>(it - frame.id.begin());
}

}  // namespace

Eigen::Vector3d positionOf(const io::FrameData& frame, std::size_t row) {
  const auto r = static_cast<Eigen::Index>(row);
  return {frame.position.x[r], frame.position.y[r], frame.position.z[r]};
}

void growBounds(const io::FrameData& frame, Eigen::Vector3d& lo, Eigen::Vector3d& hi) {
  for (std::size_t i = 0; i < frame.size(); ++i) {
    const Eigen::Vector3d p = positionOf(frame, i);
    if (!p.allFinite()) continue;
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
}

SplatImage renderFrame(const PinholeCamera& camera, const io::FrameData& frame,
                       const std::vector<Rgb>& colours,
                       const std::vector<std::pair<std::uint64_t, std::uint64_t>>& lines,
                       const RenderSettings& settings) {
  if (colours.size() != frame.size()) {
    throw std::invalid_argument("renderFrame: one colour a particle");
  }
  SplatImage image(camera.width(), camera.height(), settings.background);
  if (settings.grid) drawGroundGrid(image, camera, *settings.grid);
  if (settings.axisLength) drawAxisMarks(image, camera, *settings.axisLength);
  for (const auto& [a, b] : lines) {
    const auto ra = rowOf(frame, a), rb = rowOf(frame, b);
    if (!ra || !rb) continue;
    if (const auto s = camera.projectSegment(positionOf(frame, *ra), positionOf(frame, *rb))) {
      image.drawLine(s->first.x, s->first.y, s->second.x, s->second.y, settings.lineColour, 0.7f);
    }
  }
  const FloatColumn* pscale = nullptr;
  if (!settings.size.ignorePscale) {
    const auto it = std::find(frame.attributeNames.begin(), frame.attributeNames.end(), "pscale");
    if (it != frame.attributeNames.end()) {
      pscale = &frame.attributes[static_cast<std::size_t>(it - frame.attributeNames.begin())];
    }
  }
  // Houdini's Alpha, where the frame has it, is each splat's opacity (clamped to [0, 1]).
  const FloatColumn* alpha = nullptr;
  if (const auto it = std::find(frame.attributeNames.begin(), frame.attributeNames.end(), "Alpha");
      it != frame.attributeNames.end()) {
    alpha = &frame.attributes[static_cast<std::size_t>(it - frame.attributeNames.begin())];
  }
  std::vector<Splat> splats;
  splats.reserve(frame.size());
  for (std::size_t i = 0; i < frame.size(); ++i) {
    const auto q = camera.project(positionOf(frame, i));
    if (!q) continue;
    double radius = 0.5 * settings.size.diameterPixels;
    if (pscale != nullptr) {
      radius = (*pscale)[static_cast<Eigen::Index>(i)] * camera.pixelsPerMetre(q->depth);
    } else if (settings.size.radiusMetres) {
      radius = *settings.size.radiusMetres * camera.pixelsPerMetre(q->depth);
    }
    // Half a pixel at least, so that far or tiny particles still show; a NaN radius too.
    radius = std::clamp(std::isnan(radius) ? 0.5 : radius, 0.5, 4096.0);
    const float opacity =
        alpha != nullptr ? std::clamp((*alpha)[static_cast<Eigen::Index>(i)], 0.0f, 1.0f) : 1.0f;
    splats.push_back({static_cast<float>(q->x), static_cast<float>(q->y),
                      static_cast<float>(q->depth), static_cast<float>(radius), colours[i],
                      std::isnan(opacity) ? 1.0f : opacity});
  }
  image.draw(std::move(splats));
  return image;
}

}  // namespace tickfx::preview
