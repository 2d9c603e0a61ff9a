#include "app/preview/GifFlipbook.h"

#include <gif_lib.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <exception>
#include <new>
#include <ostream>
#include <stdexcept>
#include <string>
#include <utility>

#include "io/util/AtomicFile.h"

namespace tickfx::preview {
namespace {

// GIF stores sizes and delays as 16-bit words.
constexpr int kMaxWord = 65535;

constexpr int kRedLevels = 6, kGreenLevels = 7, kBlueLevels = 6;
constexpr int kCubeColours = kRedLevels * kGreenLevels * kBlueLevels;
// Below the smallest channel spread of a cube colour that is not black or white ((51, 43, 51)
// spreads 8), so that every cube colour still maps to itself.
constexpr int kNearGreySpread = 8;
// giflib writes the trailer only when it closes the encoder, which would end the animation;
// bytes() adds it to a copy instead, so frames can still be added after.
constexpr std::uint8_t kTrailer = 0x3B;

// The 4 × 4 Bayer matrix: every threshold once in any 4 × 4 window, neighbours far apart.
constexpr std::array<std::array<int, 4>, 4> kBayer{
    {{0, 8, 2, 10}, {12, 4, 14, 6}, {3, 11, 1, 9}, {15, 7, 13, 5}}};

// Level i of n, rounded once, so that 7 levels give 0, 43, 85, 128, 170, 213, 255.
constexpr int levelValue(int i, int levels) { return (255 * i + (levels - 1) / 2) / (levels - 1); }

using DitherTable = std::array<std::array<std::uint8_t, 256>, 16>;

// table[k][v]: the level that value v dithers to under Bayer threshold (k + 1/2) / 16. Up a level
// when v's fraction of the way between the levels around it exceeds the threshold; integers
// only, so a level's own value never rounds up and the table is the same on every machine.
DitherTable makeDitherTable(int levels) {
  DitherTable table{};
  for (int k = 0; k < 16; ++k) {
    for (int v = 0; v < 256; ++v) {
      int i = 0;
      while (i < levels - 2 && levelValue(i + 1, levels) <= v) ++i;
      const int lo = levelValue(i, levels), step = levelValue(i + 1, levels) - lo;
      const bool up = 32 * (v - lo) > (2 * k + 1) * step;
      table[static_cast<std::size_t>(k)][static_cast<std::size_t>(v)] =
          static_cast<std::uint8_t>(i + (up ? 1 : 0));
    }
  }
  return table;
}

// Grey levels (of 5: 0, 64, 128, 191, 255) for near-greys, beside the cube's black and white.
constexpr int kGreyLevels = 5;
// The palette's last slot: the frames' background colour, exactly.
constexpr std::size_t kBackgroundIndex = 255;

std::string giflibError(int code) {
  const char* s = GifErrorString(code);
  return std::string("giflib: ") + (s != nullptr ? s : "error " + std::to_string(code));
}

}  // namespace

// Named, not anonymous: an Encoder (a class with linkage) holds one.
namespace gifpalette {

struct Quantiser {
  DitherTable six = makeDitherTable(6), seven = makeDitherTable(7), five = makeDitherTable(5);
  // The palette index of grey level j of 5 (0 and 4 are the cube's black and white).
  std::array<std::uint8_t, kGreyLevels> grey{0, kCubeColours, kCubeColours + 1, kCubeColours + 2,
                                             kCubeColours - 1};
  Rgb background;
  std::array<GifColorType, 256> palette{};

  explicit Quantiser(Rgb bg) : background(bg) {
    for (int r = 0; r < kRedLevels; ++r) {
      for (int g = 0; g < kGreenLevels; ++g) {
        for (int b = 0; b < kBlueLevels; ++b) {
          palette[static_cast<std::size_t>(cubeIndex(r, g, b))] = {
              static_cast<GifByteType>(levelValue(r, kRedLevels)),
              static_cast<GifByteType>(levelValue(g, kGreenLevels)),
              static_cast<GifByteType>(levelValue(b, kBlueLevels))};
        }
      }
    }
    for (int j = 1; j < kGreyLevels - 1; ++j) {
      const auto v = static_cast<GifByteType>(levelValue(j, kGreyLevels));
      palette[grey[static_cast<std::size_t>(j)]] = {v, v, v};
    }
    palette[kBackgroundIndex] = {background[0], background[1], background[2]};
  }

  static int cubeIndex(int r, int g, int b) { return (r * kGreenLevels + g) * kBlueLevels + b; }

  GifPixelType index(int x, int y, Rgb c) const {
    // Most of a frame: one index, no dither, so the background is flat and compresses to little.
    if (c == background) return static_cast<GifPixelType>(kBackgroundIndex);
    const auto k = static_cast<std::size_t>(
        kBayer[static_cast<std::size_t>(y & 3)][static_cast<std::size_t>(x & 3)]);
    const auto [lo, hi] = std::minmax({c[0], c[1], c[2]});
    if (hi - lo < kNearGreySpread) {
      const int mean = (c[0] + c[1] + c[2] + 1) / 3;
      return grey[five[k][static_cast<std::size_t>(mean)]];
    }
    return static_cast<GifPixelType>(cubeIndex(six[k][c[0]], seven[k][c[1]], six[k][c[2]]));
  }
};

}  // namespace gifpalette

struct GifFlipbook::Encoder {
  int width, height, delay;
  gifpalette::Quantiser quantiser;
  std::vector<std::uint8_t> header;               // signature, screen, palette, loop extension
  std::vector<std::vector<std::uint8_t>> frames;  // each frame's extension and image, exact size
  // Where giflib's writes go: the header, then each frame's scratch. The scratch keeps its
  // capacity from frame to frame, so a frame is copied once, at its own size, into `frames`.
  std::vector<std::uint8_t> scratch;
  std::vector<std::uint8_t>* target = nullptr;
  // giflib is C: nothing may unwind through it. The output callback keeps what it caught here
  // and refuses every write after, and check() throws it once giflib has returned.
  std::exception_ptr writeFailure;
  struct Close {
    void operator()(GifFileType* file) const { EGifCloseFile(file, nullptr); }
  };
  // Declared last, so destroyed first: its close may write to the buffers above.
  std::unique_ptr<GifFileType, Close> gif;

  static int append(GifFileType* file, const GifByteType* data, int size) {
    auto& self = *static_cast<Encoder*>(file->UserData);
    if (self.target == nullptr || self.writeFailure || size < 0) return 0;
    try {
      self.target->insert(self.target->end(), data, data + size);
    } catch (...) {
      self.writeFailure = std::current_exception();
      return 0;
    }
    return size;
  }

  void check(int result) {
    if (writeFailure) {
      std::exception_ptr failure = std::exchange(writeFailure, nullptr);
      std::rethrow_exception(failure);
    }
    if (result != GIF_OK) throw std::runtime_error(giflibError(gif->Error));
  }

  Encoder(int w, int h, int d, Rgb background)
      : width(w), height(h), delay(d), quantiser(background) {
    int error = 0;
    gif.reset(EGifOpen(this, &Encoder::append, &error));
    if (!gif) throw std::runtime_error(giflibError(error));
    target = &header;
    // The graphics control and application extensions are GIF89a's; giflib would otherwise
    // write GIF87a, the signature being written before any of them.
    EGifSetGifVersion(gif.get(), true);
    ColorMapObject* map = GifMakeMapObject(256, quantiser.palette.data());
    if (map == nullptr) throw std::bad_alloc();
    const int screen = EGifPutScreenDesc(gif.get(), width, height, 8, 0, map);
    GifFreeMapObject(map);
    check(screen);
    // NETSCAPE2.0 sub-block 1 is the loop count, a little-endian word; 0 loops forever.
    static constexpr char kApplication[] = "NETSCAPE2.0";
    static constexpr GifByteType kLoopForever[] = {1, 0, 0};
    check(EGifPutExtensionLeader(gif.get(), APPLICATION_EXT_FUNC_CODE));
    check(EGifPutExtensionBlock(gif.get(), 11, kApplication));
    check(EGifPutExtensionBlock(gif.get(), 3, kLoopForever));
    check(EGifPutExtensionTrailer(gif.get()));
    target = nullptr;
  }

  ~Encoder() { target = nullptr; }  // the close's trailer goes nowhere

  Encoder(const Encoder&) = delete;
  Encoder& operator=(const Encoder&) = delete;

  void put(const SplatImage& image) {
    scratch.clear();
    target = &scratch;
    GraphicsControlBlock control{};
    control.DisposalMode = DISPOSE_DO_NOT;  // each frame covers the whole screen anyway
    control.UserInputFlag = false;
    control.DelayTime = delay;
    control.TransparentColor = NO_TRANSPARENT_COLOR;
    GifByteType extension[4];
    const auto length = static_cast<int>(EGifGCBToExtension(&control, extension));
    check(EGifPutExtension(gif.get(), GRAPHICS_EXT_FUNC_CODE, length, extension));
    // No local palette: every frame uses the global one.
    check(EGifPutImageDesc(gif.get(), 0, 0, width, height, false, nullptr));
    const gifpalette::Quantiser& q = quantiser;
    const std::vector<std::uint8_t> rgb = image.rgb8();
    std::vector<GifPixelType> row(static_cast<std::size_t>(width));
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        const std::uint8_t* c = &rgb[(static_cast<std::size_t>(y) * width + x) * 3];
        row[static_cast<std::size_t>(x)] = q.index(x, y, {c[0], c[1], c[2]});
      }
      check(EGifPutLine(gif.get(), row.data(), width));
    }
    target = nullptr;
    frames.emplace_back(scratch.begin(), scratch.end());
  }
};

GifFlipbook::GifFlipbook(int width, int height, int delayCentiseconds, Rgb background) {
  if (width < 1 || height < 1 || width > kMaxWord || height > kMaxWord) {
    throw std::invalid_argument("a flipbook of " + std::to_string(width) + "x" +
                                std::to_string(height) + " pixels (expected 1 to " +
                                std::to_string(kMaxWord) + " a side)");
  }
  if (delayCentiseconds < 1 || delayCentiseconds > kMaxWord) {
    throw std::invalid_argument("a frame delay of " + std::to_string(delayCentiseconds) +
                                " centiseconds (expected 1 to " + std::to_string(kMaxWord) + ")");
  }
  encoder_ = std::make_unique<Encoder>(width, height, delayCentiseconds, background);
}

GifFlipbook::~GifFlipbook() = default;
GifFlipbook::GifFlipbook(GifFlipbook&&) noexcept = default;
GifFlipbook& GifFlipbook::operator=(GifFlipbook&&) noexcept = default;

void GifFlipbook::add(const SplatImage& image) {
  Encoder& e = *encoder_;
  if (image.width() != e.width || image.height() != e.height) {
    throw std::invalid_argument("a frame of " + std::to_string(image.width()) + "x" +
                                std::to_string(image.height()) + " pixels in a flipbook of " +
                                std::to_string(e.width) + "x" + std::to_string(e.height));
  }
  // A frame that fails leaves `frames` as it was, and giflib's compressor half-way through an
  // image: the next image descriptor resets it (its code size, bit buffer and string table).
  try {
    e.put(image);
  } catch (...) {
    e.target = nullptr;
    throw;
  }
}

std::size_t GifFlipbook::frameCount() const { return encoder_->frames.size(); }
int GifFlipbook::width() const { return encoder_->width; }
int GifFlipbook::height() const { return encoder_->height; }

std::vector<std::uint8_t> GifFlipbook::bytes() const {
  const Encoder& e = *encoder_;
  std::size_t size = e.header.size() + 1;
  for (const auto& frame : e.frames) size += frame.size();
  std::vector<std::uint8_t> out;
  out.reserve(size);
  out.insert(out.end(), e.header.begin(), e.header.end());
  for (const auto& frame : e.frames) out.insert(out.end(), frame.begin(), frame.end());
  out.push_back(kTrailer);
  return out;
}

void GifFlipbook::write(const std::filesystem::path& path) const {
  const Encoder& e = *encoder_;
  // Piece by piece: a copy of the whole animation would double the memory at its peak.
  io::writeFileAtomically(path, [&](std::ostream& out) {
    const auto put = [&](const std::vector<std::uint8_t>& bytes) {
      out.write(reinterpret_cast<const char*>(bytes.data()),
                static_cast<std::streamsize>(bytes.size()));
    };
    put(e.header);
    for (const auto& frame : e.frames) put(frame);
    out.put(static_cast<char>(kTrailer));
  });
}

int GifFlipbook::delayFor(double fps) {
  if (!std::isfinite(fps) || !(fps > 0.0)) {
    throw std::invalid_argument("a frame rate of " + std::to_string(fps) +
                                " frames per second (expected a positive number)");
  }
  return static_cast<int>(std::clamp(std::round(100.0 / fps), 2.0, static_cast<double>(kMaxWord)));
}

}  // namespace tickfx::preview
