#include "app/preview/SceneGuides.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "app/preview/ColourMap.h"
#include "app/preview/PixelFont.h"

namespace tickfx::preview {
namespace {

constexpr Rgb kGridColour{72, 72, 82};
constexpr Rgb kTextColour{235, 235, 235};
constexpr Rgb kBoxColour{0, 0, 0};

// The ground axes' indices in a world vector: (x, z) under y up, (x, y) under z up.
std::pair<int, int> groundAxes(UpAxis up) {
  return up == UpAxis::Y ? std::pair{0, 2} : std::pair{0, 1};
}

Eigen::Vector3d groundPoint(UpAxis up, double a, double b) {
  const auto [i, j] = groundAxes(up);
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  p[i] = a;
  p[j] = b;
  return p;
}

void drawSegment(SplatImage& image, const PinholeCamera& camera, const Eigen::Vector3d& a,
                 const Eigen::Vector3d& b, Rgb colour, float opacity) {
  if (const auto s = camera.projectSegment(a, b)) {
    image.drawLine(s->first.x, s->first.y, s->second.x, s->second.y, colour, opacity);
  }
}

std::string shortNumber(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", v);
  return text;
}

}  // namespace

Eigen::Vector3d upVector(UpAxis up) {
  return up == UpAxis::Y ? Eigen::Vector3d::UnitY() : Eigen::Vector3d::UnitZ();
}

std::optional<GroundGrid> GroundGrid::under(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                                            UpAxis up) {
  const auto [i, j] = groundAxes(up);
  GroundGrid grid;
  grid.up = up;
  const double widest = std::max(hi[i] - lo[i], hi[j] - lo[j]);
  if (!std::isfinite(widest)) return std::nullopt;
  // Whole decades, so that every line still falls on a whole metre.
  while (widest / grid.spacing + 2.0 > kMaxLines) {
    grid.spacing *= 10.0;
    if (grid.spacing > 1e12) return std::nullopt;
  }
  const auto out = [&](double v, double side) {
    return (side < 0 ? std::floor(v / grid.spacing) : std::ceil(v / grid.spacing)) * grid.spacing +
           side * grid.spacing;
  };
  grid.lo = {out(lo[i], -1.0), out(lo[j], -1.0)};
  grid.hi = {out(hi[i], 1.0), out(hi[j], 1.0)};
  return grid;
}

void drawGroundGrid(SplatImage& image, const PinholeCamera& camera, const GroundGrid& grid) {
  const auto lines = [&](int axis) {
    const double from = grid.lo[axis], to = grid.hi[axis];
    const double otherFrom = grid.lo[1 - axis], otherTo = grid.hi[1 - axis];
    const auto count = static_cast<long long>(std::llround((to - from) / grid.spacing));
    for (long long k = 0; k <= count; ++k) {
      const double at = from + static_cast<double>(k) * grid.spacing;
      const Eigen::Vector3d a =
          axis == 0 ? groundPoint(grid.up, at, otherFrom) : groundPoint(grid.up, otherFrom, at);
      const Eigen::Vector3d b =
          axis == 0 ? groundPoint(grid.up, at, otherTo) : groundPoint(grid.up, otherTo, at);
      drawSegment(image, camera, a, b, kGridColour, 1.0f);
    }
  };
  lines(0);
  lines(1);
}

void drawAxisMarks(SplatImage& image, const PinholeCamera& camera, double length) {
  const struct {
    Eigen::Vector3d direction;
    Rgb colour;
    const char* name;
  } axes[] = {{Eigen::Vector3d::UnitX(), {230, 80, 80}, "x"},
              {Eigen::Vector3d::UnitY(), {90, 210, 90}, "y"},
              {Eigen::Vector3d::UnitZ(), {90, 130, 240}, "z"}};
  for (const auto& axis : axes) {
    const Eigen::Vector3d tip = length * axis.direction;
    drawSegment(image, camera, Eigen::Vector3d::Zero(), tip, axis.colour, 1.0f);
    if (const auto q = camera.project(tip * 1.08)) {
      if (std::abs(q->x) < 1e6 && std::abs(q->y) < 1e6) {
        drawText(image, static_cast<int>(std::floor(q->x)) - 2,
                 static_cast<int>(std::floor(q->y)) - kGlyphHeight / 2, axis.name, axis.colour, 1);
      }
    }
  }
}

void drawLegend(SplatImage& image, std::string_view title, double lo, double hi, int scale) {
  const int pad = 2 * scale;
  const int barWidth = std::max(16, std::min(256, image.width() / 4));
  const int barHeight = 5 * scale;
  const std::string low = shortNumber(lo), high = shortNumber(hi);
  const int textHeight = kGlyphHeight * scale;
  const int boxWidth =
      std::max({barWidth, textWidth(title, scale), textWidth(low + "  " + high, scale)}) + 2 * pad;
  const int boxHeight = 2 * textHeight + barHeight + 4 * pad;
  const int x0 = 0, y0 = image.height() - boxHeight;
  fillRect(image, x0, y0, x0 + boxWidth, image.height(), kBoxColour);
  drawText(image, x0 + pad, y0 + pad, title, kTextColour, scale);
  const int barTop = y0 + textHeight + 2 * pad;
  for (int x = 0; x < barWidth; ++x) {
    const Rgb c = viridis((static_cast<double>(x) + 0.5) / barWidth);
    fillRect(image, x0 + pad + x, barTop, x0 + pad + x + 1, barTop + barHeight, c);
  }
  const int labelTop = barTop + barHeight + pad;
  drawText(image, x0 + pad, labelTop, low, kTextColour, scale);
  drawText(image, x0 + pad + barWidth - textWidth(high, scale), labelTop, high, kTextColour, scale);
}

void drawCaption(SplatImage& image, std::string_view text, int scale) {
  const int pad = 2 * scale;
  fillRect(image, 0, 0, textWidth(text, scale) + 2 * pad, kGlyphHeight * scale + 2 * pad,
           kBoxColour);
  drawText(image, pad, pad, text, kTextColour, scale);
}

}  // namespace tickfx::preview
