// Preview frames as one looping animated GIF, for a browser or a chat window.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <vector>

#include "app/preview/SplatImage.h"

namespace tickfx::preview {

/// A looping animated GIF built frame by frame in memory and written whole at the end.
///
/// Every frame is quantised to one fixed palette of 256 colours (a 6 × 7 × 6 RGB cube, 6 levels
/// of red and blue and 7 of green evenly spread over 0..255, the greys 64, 128 and 191, and the
/// frames' background colour) with a 4 × 4 ordered dither, so a pixel's index depends only on its
/// colour and its position: the same frames give the same bytes whatever else is in them. A
/// palette colour is kept exactly, the background among them, so that most of a frame is one
/// flat colour; another colour becomes a pattern of its neighbours in the palette whose mean over
/// any 4 × 4 pixels is within 2 of it in each channel. Near-greys (channels within 7 of each
/// other) are dithered between greys only, so that they pick up no tint: their mean is within 2
/// of the channels' mean.
///
/// Frames are compressed as they are added: memory is the compressed animation, not its pixels.
/// Move-only; a moved-from flipbook may only be destroyed or assigned to.
class GifFlipbook {
 public:
  /// Frames of width × height pixels shown `delayCentiseconds` each (GIF counts delays in
  /// 1/100 s), on `background` (RenderSettings::background: the palette holds it exactly).
  /// Throws std::invalid_argument for a size outside 1..65535 or a delay outside 1..65535.
  GifFlipbook(int width, int height, int delayCentiseconds, Rgb background);
  ~GifFlipbook();
  GifFlipbook(GifFlipbook&&) noexcept;
  GifFlipbook& operator=(GifFlipbook&&) noexcept;

  /// Appends `image` (must be width × height, else std::invalid_argument), quantised to the
  /// fixed palette. Time and memory are those of this frame alone. If it throws (out of memory),
  /// the flipbook is as it was before the call.
  void add(const SplatImage& image);
  std::size_t frameCount() const;
  int width() const;
  int height() const;

  /// The whole GIF (GIF89a, NETSCAPE2.0 loop-forever extension, one global palette) as bytes.
  /// With no frames this is a valid GIF of no images, which most viewers refuse to show.
  std::vector<std::uint8_t> bytes() const;
  /// Writes bytes() to `path` atomically (io/util/AtomicFile.h); throws WriteError.
  void write(const std::filesystem::path& path) const;

  /// The delay (centiseconds) that best shows `fps` frames per second: round(100 / fps), at least
  /// 2 (browsers show 0 and 1 as 10) and at most 65535. Throws std::invalid_argument unless fps
  /// is finite and positive.
  static int delayFor(double fps);

 private:
  struct Encoder;  // giflib's encoder and the bytes it has written so far
  std::unique_ptr<Encoder> encoder_;
};

}  // namespace tickfx::preview
