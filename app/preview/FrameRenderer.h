// One frame of particles rendered as a preview: guides, springs as lines, then the splats.
#pragma once

#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include "app/preview/PinholeCamera.h"
#include "app/preview/SceneGuides.h"
#include "app/preview/SplatImage.h"
#include "io/cache/FrameData.h"

namespace tickfx::preview {

/// How big a splat is. A frame with a `pscale` attribute (Houdini's radius, metres) is drawn at
/// that size unless `ignorePscale`; otherwise every particle is `radiusMetres` across the view
/// when given, else `diameterPixels` on screen. No splat is drawn narrower than one pixel.
struct SplatSize {
  double diameterPixels = 3.0;
  std::optional<double> radiusMetres;
  bool ignorePscale = false;
};

/// Row `row`'s position in `frame`, metres, widened to double for the camera.
Eigen::Vector3d positionOf(const io::FrameData& frame, std::size_t row);

/// Grows the box [lo, hi] to hold every finite position of `frame` (a particle gone to infinity
/// or NaN would make the box useless for framing). Start from lo = +inf, hi = -inf.
void growBounds(const io::FrameData& frame, Eigen::Vector3d& lo, Eigen::Vector3d& hi);

/// What renderFrame draws besides the particles.
struct RenderSettings {
  Rgb background{24, 24, 28};
  SplatSize size;
  std::optional<GroundGrid> grid;    // the ground grid, or none
  std::optional<double> axisLength;  // axis marks of this many metres, or none
  Rgb lineColour{150, 150, 165};     // springs
};

/// Renders `frame` as `camera` sees it: the grid and axis marks, then `lines` (pairs of ids, such
/// as a structure's springs; pairs naming an id not in the frame are skipped), then each row as a
/// round splat of `colours[row]` at the frame's `Alpha` as opacity (opaque without it), nearer
/// over farther. The bytes depend only on the arguments, not on the thread count.
SplatImage renderFrame(const PinholeCamera& camera, const io::FrameData& frame,
                       const std::vector<Rgb>& colours,
                       const std::vector<std::pair<std::uint64_t, std::uint64_t>>& lines,
                       const RenderSettings& settings);

}  // namespace tickfx::preview
