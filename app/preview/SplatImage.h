// Particles drawn as round splats into an RGB image, and the image written as a PNG.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <vector>

namespace tickfx::preview {

using Rgb = std::array<std::uint8_t, 3>;

/// One particle as the image sees it: its centre in pixels (PinholeCamera::project), its depth
/// (metres; farther splats are drawn first), its radius in pixels, its colour and its opacity
/// (Houdini's Alpha: 0 transparent to 1 opaque).
struct Splat {
  float x = 0.0f;
  float y = 0.0f;
  float depth = 0.0f;
  float radius = 1.0f;
  Rgb colour{255, 255, 255};
  float opacity = 1.0f;
};

/// An 8-bit RGB image, rows top to bottom.
class SplatImage {
 public:
  /// Throws std::invalid_argument unless 1 <= width, height <= kMaxSide.
  SplatImage(int width, int height, Rgb background);

  static constexpr int kMaxSide = 16384;

  /// Draws `splats` over the image, farthest first (ties in the order given), each a disc of its
  /// radius whose edge is blended over one pixel. Runs in parallel bands of rows on the calling
  /// thread's TBB arena; every pixel sees the same splats in the same order, so the bytes do not
  /// depend on the thread count.
  void draw(std::vector<Splat> splats);

  /// Draws an antialiased line one pixel wide from (x0, y0) to (x1, y1) (pixel coordinates as
  /// Splat's), blended over the image with `opacity` in [0, 1]; the parts outside the image are
  /// skipped. Serial: guides and springs are few next to the particles.
  void drawLine(double x0, double y0, double x1, double y1, Rgb colour, float opacity);

  /// Sets one pixel (frames, legends).
  void set(int x, int y, Rgb colour);
  Rgb at(int x, int y) const;
  int width() const { return width_; }
  int height() const { return height_; }

  /// The image as 8-bit RGB, 3 bytes a pixel, rows top to bottom: what at() gives for every
  /// pixel, converted in parallel. What the PNG, GIF and movie writers encode.
  std::vector<std::uint8_t> rgb8() const;
  /// The image as PNG bytes (8-bit RGB, no metadata: the same image gives the same bytes).
  std::vector<std::uint8_t> png() const;
  /// Writes png() to `path` atomically (io/util/AtomicFile.h); throws WriteError.
  void writePng(const std::filesystem::path& path) const;

 private:
  int width_, height_;
  std::vector<float> rgb_;  // 3 floats a pixel, 0..255, blended in float and rounded once
};

}  // namespace tickfx::preview
