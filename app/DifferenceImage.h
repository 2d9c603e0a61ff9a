// Determinism you can see: where two runs that should agree have parted.
#pragma once

#include <cstdint>
#include <string>

#include "app/preview/SplatImage.h"
#include "io/cache/FrameData.h"

namespace tickfx::app {

/// What a difference image found.
struct DifferenceSummary {
  std::size_t differing = 0;  // particles whose positions differ, or that one run lacks
  double largest = 0.0;       // metres: the largest distance between a particle's two positions
};

/// Renders `a` (the state of one run after `tick`) with each particle, matched to `b` by id,
/// coloured through viridis by the distance between its two positions (0 to the largest), a
/// particle only one run has at the top colour, over a ground grid, the camera framing both
/// states. The caption names the tick and the runs (`labelA`, `labelB`); the legend gives the
/// range in metres. Fills `summary` when given.
preview::SplatImage renderDifference(const io::FrameData& a, const io::FrameData& b,
                                     const std::string& labelA, const std::string& labelB,
                                     std::int64_t tick, int width, int height,
                                     DifferenceSummary* summary = nullptr);

}  // namespace tickfx::app
