// GIF flipbooks, read back through giflib's decoder: the frames, the palette, the delay and the
// loop come back as written, the dither keeps colours on average, the bytes depend on the frames
// alone, and bad sizes, delays and paths are refused.
#include <gif_lib.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <memory>
#include <random>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/preview/GifFlipbook.h"
#include "app/preview/SplatImage.h"
#include "io/util/AtomicFile.h"

namespace tickfx::preview {

using io::WriteError;
namespace {

const Rgb kBlack{0, 0, 0}, kWhite{255, 255, 255}, kRed{255, 0, 0}, kGrey64{64, 64, 64},
    kGrey128{128, 128, 128}, kGrey191{191, 191, 191}, kOrange{204, 85, 51}, kTeal{0, 170, 153};
// The frames' background, which the palette holds exactly (the preview's own).
const Rgb kBackground{24, 24, 28};

struct CloseDecoder {
  void operator()(GifFileType* gif) const { DGifCloseFile(gif, nullptr); }
};
using Decoded = std::unique_ptr<GifFileType, CloseDecoder>;

struct MemoryReader {
  const std::vector<std::uint8_t>& bytes;
  std::size_t at = 0;
};

int readMemory(GifFileType* gif, GifByteType* out, int size) {
  auto& reader = *static_cast<MemoryReader*>(gif->UserData);
  const std::size_t n = std::min(static_cast<std::size_t>(size), reader.bytes.size() - reader.at);
  std::memcpy(out, reader.bytes.data() + reader.at, n);
  reader.at += n;
  return static_cast<int>(n);
}

// The GIF as giflib's decoder reads it, every image in memory.
Decoded decode(const std::vector<std::uint8_t>& bytes) {
  MemoryReader reader{bytes};
  int error = 0;
  Decoded gif(DGifOpen(&reader, readMemory, &error));
  if (!gif) throw std::runtime_error("DGifOpen failed: error " + std::to_string(error));
  if (DGifSlurp(gif.get()) != GIF_OK) {
    throw std::runtime_error("DGifSlurp failed: error " + std::to_string(gif->Error));
  }
  gif->UserData = nullptr;  // everything is read: `reader` goes now
  return gif;
}

Rgb pixel(const GifFileType& gif, int frame, int x, int y) {
  const SavedImage& image = gif.SavedImages[frame];
  const ColorMapObject* map =
      image.ImageDesc.ColorMap != nullptr ? image.ImageDesc.ColorMap : gif.SColorMap;
  const GifByteType index = image.RasterBits[y * image.ImageDesc.Width + x];
  const GifColorType c = map->Colors[index];
  return {c.Red, c.Green, c.Blue};
}

SplatImage noise(int width, int height, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_int_distribution<int> channel(0, 255);
  SplatImage image(width, height, kBlack);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      image.set(
          x, y,
          {static_cast<std::uint8_t>(channel(random)), static_cast<std::uint8_t>(channel(random)),
           static_cast<std::uint8_t>(channel(random))});
    }
  }
  return image;
}

// Two 8 × 6 frames of palette colours only.
SplatImage firstFrame() {
  SplatImage image(8, 6, kBlack);
  image.set(1, 1, kWhite);
  image.set(2, 1, kRed);
  image.set(3, 1, kGrey64);
  image.set(4, 1, kGrey191);
  image.set(5, 1, kOrange);
  image.set(7, 5, kTeal);
  return image;
}

SplatImage secondFrame() {
  SplatImage image(8, 6, kWhite);
  image.set(0, 0, kBlack);
  image.set(6, 2, kRed);
  image.set(2, 4, kGrey191);
  image.set(3, 4, kGrey64);
  return image;
}

TEST(GifFlipbook, DecodesToTheFramesWithTheirDelayAndLoopsForever) {
  const SplatImage frames[] = {firstFrame(), secondFrame()};
  GifFlipbook book(8, 6, 7, kBackground);
  EXPECT_EQ(book.frameCount(), 0u);
  book.add(frames[0]);
  book.add(frames[1]);
  EXPECT_EQ(book.frameCount(), 2u);
  const std::vector<std::uint8_t> bytes = book.bytes();
  ASSERT_GT(bytes.size(), 6u);
  EXPECT_EQ(std::string(bytes.begin(), bytes.begin() + 6), "GIF89a");
  EXPECT_EQ(bytes.back(), 0x3B);  // the trailer

  const Decoded gif = decode(bytes);
  EXPECT_EQ(gif->SWidth, 8);
  EXPECT_EQ(gif->SHeight, 6);
  ASSERT_EQ(gif->ImageCount, 2);
  ASSERT_NE(gif->SColorMap, nullptr);
  EXPECT_EQ(gif->SColorMap->ColorCount, 256);
  for (int f = 0; f < 2; ++f) {
    const GifImageDesc& desc = gif->SavedImages[f].ImageDesc;
    EXPECT_EQ(desc.Left, 0);
    EXPECT_EQ(desc.Top, 0);
    EXPECT_EQ(desc.Width, 8);
    EXPECT_EQ(desc.Height, 6);
    EXPECT_FALSE(desc.Interlace);
    EXPECT_EQ(desc.ColorMap, nullptr);  // the global palette
    for (int y = 0; y < 6; ++y) {
      for (int x = 0; x < 8; ++x) {
        EXPECT_EQ(pixel(*gif, f, x, y), frames[f].at(x, y))
            << "frame " << f << " at " << x << "," << y;
      }
    }
    GraphicsControlBlock control{};
    ASSERT_EQ(DGifSavedExtensionToGCB(gif.get(), f, &control), GIF_OK);
    EXPECT_EQ(control.DelayTime, 7);
    EXPECT_EQ(control.TransparentColor, NO_TRANSPARENT_COLOR);
  }

  // The extensions before the first image are the loop's and its graphics control; the second
  // image has its graphics control alone.
  const SavedImage& first = gif->SavedImages[0];
  int loops = 0;
  for (int i = 0; i < first.ExtensionBlockCount; ++i) {
    const ExtensionBlock& block = first.ExtensionBlocks[i];
    if (block.Function != APPLICATION_EXT_FUNC_CODE) continue;
    ++loops;
    ASSERT_EQ(block.ByteCount, 11);
    EXPECT_EQ(std::string(block.Bytes, block.Bytes + 11), "NETSCAPE2.0");
    ASSERT_LT(i + 1, first.ExtensionBlockCount);
    const ExtensionBlock& count = first.ExtensionBlocks[i + 1];
    EXPECT_EQ(count.Function, CONTINUE_EXT_FUNC_CODE);
    ASSERT_EQ(count.ByteCount, 3);
    EXPECT_EQ(count.Bytes[0], 1);                          // sub-block 1: the loop count
    EXPECT_EQ(count.Bytes[1] | (count.Bytes[2] << 8), 0);  // 0: forever
  }
  EXPECT_EQ(loops, 1);
  const SavedImage& second = gif->SavedImages[1];
  ASSERT_EQ(second.ExtensionBlockCount, 1);
  EXPECT_EQ(second.ExtensionBlocks[0].Function, GRAPHICS_EXT_FUNC_CODE);
}

TEST(GifFlipbook, HasTheFixedPaletteOfACubeThreeGreysAndTheBackground) {
  GifFlipbook book(1, 1, 10, kBackground);
  book.add(SplatImage(1, 1, kBlack));
  const Decoded gif = decode(book.bytes());
  ASSERT_NE(gif->SColorMap, nullptr);
  std::set<Rgb> palette;
  for (int i = 0; i < gif->SColorMap->ColorCount; ++i) {
    const GifColorType c = gif->SColorMap->Colors[i];
    palette.insert({c.Red, c.Green, c.Blue});
  }
  std::set<Rgb> expected;
  const std::array<std::uint8_t, 6> sixes{0, 51, 102, 153, 204, 255};
  const std::array<std::uint8_t, 7> sevens{0, 43, 85, 128, 170, 213, 255};
  for (const std::uint8_t r : sixes) {
    for (const std::uint8_t g : sevens) {
      for (const std::uint8_t b : sixes) expected.insert({r, g, b});
    }
  }
  for (const std::uint8_t v : std::array<std::uint8_t, 3>{64, 128, 191}) expected.insert({v, v, v});
  expected.insert(kBackground);
  EXPECT_EQ(expected.size(), 256u);
  EXPECT_EQ(palette, expected);
}

// The background is one palette colour: a frame of it is flat (and compresses to a few bytes a
// row), where a colour one step off it is dithered.
TEST(GifFlipbook, KeepsTheBackgroundExactAndFlat) {
  constexpr int kWidth = 64, kHeight = 48;
  SplatImage frame(kWidth, kHeight, kBackground);
  frame.set(10, 10, kWhite);
  GifFlipbook book(kWidth, kHeight, 10, kBackground);
  book.add(frame);
  const std::vector<std::uint8_t> bytes = book.bytes();
  const Decoded gif = decode(bytes);
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      EXPECT_EQ(pixel(*gif, 0, x, y), x == 10 && y == 10 ? kWhite : kBackground) << x << "," << y;
    }
  }

  const Rgb offBackground{25, 24, 28};
  GifFlipbook other(kWidth, kHeight, 10, kBackground);
  other.add(SplatImage(kWidth, kHeight, offBackground));
  const std::vector<std::uint8_t> otherBytes = other.bytes();
  const Decoded dithered = decode(otherBytes);
  std::set<Rgb> colours;
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) colours.insert(pixel(*dithered, 0, x, y));
  }
  // Both files are alike up to the image data (header, palette, loop, image descriptor): past
  // that, the flat image takes less than half the dithered one's bytes (96 bytes against 239).
  const auto differ = std::mismatch(bytes.begin(), bytes.end(), otherBytes.begin()).first;
  const auto shared = static_cast<std::size_t>(differ - bytes.begin());
  EXPECT_GT(shared, 800u);
  EXPECT_LT(bytes.size() - shared, (otherBytes.size() - shared) / 2);
  EXPECT_EQ(colours, (std::set<Rgb>{kBlack, kGrey64}));  // a near-grey, dithered between greys
}

// The decoded mean of each 4 × 4 window of a flat image, per channel.
std::vector<std::array<double, 3>> windowMeans(const GifFileType& gif, int side) {
  std::vector<std::array<double, 3>> means;
  for (int y0 = 0; y0 + 4 <= side; ++y0) {
    for (int x0 = 0; x0 + 4 <= side; ++x0) {
      std::array<double, 3> sum{};
      for (int y = y0; y < y0 + 4; ++y) {
        for (int x = x0; x < x0 + 4; ++x) {
          const Rgb c = pixel(gif, 0, x, y);
          for (int k = 0; k < 3; ++k) sum[k] += c[k];
        }
      }
      for (double& s : sum) s /= 16.0;
      means.push_back(sum);
    }
  }
  return means;
}

std::set<Rgb> coloursIn(const GifFileType& gif, int side) {
  std::set<Rgb> colours;
  for (int y = 0; y < side; ++y) {
    for (int x = 0; x < side; ++x) colours.insert(pixel(gif, 0, x, y));
  }
  return colours;
}

TEST(GifFlipbook, DithersAColourOffThePaletteToItsMeanOverEveryFourByFour) {
  constexpr int kSide = 12;
  const Rgb colours[] = {{96, 96, 96}, {200, 100, 60}, {30, 240, 120}, {1, 254, 77}};
  for (const Rgb& colour : colours) {
    GifFlipbook book(kSide, kSide, 10, kBackground);
    book.add(SplatImage(kSide, kSide, colour));
    const Decoded gif = decode(book.bytes());
    EXPECT_GT(coloursIn(*gif, kSide).size(), 1u);  // a pattern, not the nearest colour
    for (const auto& mean : windowMeans(*gif, kSide)) {
      for (int k = 0; k < 3; ++k) EXPECT_NEAR(mean[k], colour[k], 2.0) << int(colour[k]);
    }
  }
}

TEST(GifFlipbook, DithersANearGreyBetweenGreysOnly) {
  constexpr int kSide = 8;
  GifFlipbook book(kSide, kSide, 10, kBackground);
  book.add(SplatImage(kSide, kSide, {99, 92, 97}));  // spread 7, mean 96
  const Decoded gif = decode(book.bytes());
  EXPECT_EQ(coloursIn(*gif, kSide), (std::set<Rgb>{kGrey64, kGrey128}));
  for (const auto& mean : windowMeans(*gif, kSide)) {
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(mean[k], 96.0, 2.0);
  }
}

TEST(GifFlipbook, GivesAPixelItsIndexFromItsColourAndPlaceAlone) {
  // Two frames that differ in their left halves only decode alike in their right halves.
  const SplatImage a = noise(32, 16, 1);
  SplatImage b = noise(32, 16, 2);
  for (int y = 0; y < 16; ++y) {
    for (int x = 16; x < 32; ++x) b.set(x, y, a.at(x, y));
  }
  GifFlipbook book(32, 16, 10, kBackground);
  book.add(a);
  book.add(b);
  const Decoded gif = decode(book.bytes());
  ASSERT_EQ(gif->ImageCount, 2);
  int leftDifferences = 0;
  for (int y = 0; y < 16; ++y) {
    for (int x = 0; x < 32; ++x) {
      if (x >= 16) {
        EXPECT_EQ(pixel(*gif, 0, x, y), pixel(*gif, 1, x, y)) << x << "," << y;
      } else if (pixel(*gif, 0, x, y) != pixel(*gif, 1, x, y)) {
        ++leftDifferences;
      }
    }
  }
  EXPECT_GT(leftDifferences, 200);
}

TEST(GifFlipbook, GivesTheSameBytesForTheSameFrames) {
  const auto build = [] {
    GifFlipbook book(48, 32, 4, kBackground);
    for (unsigned seed = 1; seed <= 3; ++seed) book.add(noise(48, 32, seed));
    return book.bytes();
  };
  const std::vector<std::uint8_t> once = build();
  EXPECT_GT(once.size(), 3u * 48u * 32u);  // noise hardly compresses
  EXPECT_EQ(build(), once);
}

TEST(GifFlipbook, RefusesBadSizesDelaysAndFrames) {
  EXPECT_THROW(GifFlipbook(0, 6, 10, kBackground), std::invalid_argument);
  EXPECT_THROW(GifFlipbook(8, 0, 10, kBackground), std::invalid_argument);
  EXPECT_THROW(GifFlipbook(-1, 6, 10, kBackground), std::invalid_argument);
  EXPECT_THROW(GifFlipbook(65536, 6, 10, kBackground), std::invalid_argument);
  EXPECT_THROW(GifFlipbook(8, 65536, 10, kBackground), std::invalid_argument);
  EXPECT_THROW(GifFlipbook(8, 6, 0, kBackground), std::invalid_argument);
  EXPECT_THROW(GifFlipbook(8, 6, 65536, kBackground), std::invalid_argument);
  EXPECT_NO_THROW(GifFlipbook(65535, 65535, 65535, kBackground));
  try {
    [[maybe_unused]] const GifFlipbook book(0, 720, 4, kBackground);
    ADD_FAILURE() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "a flipbook of 0x720 pixels (expected 1 to 65535 a side)");
  }
  try {
    [[maybe_unused]] const GifFlipbook book(1280, 720, 0, kBackground);
    ADD_FAILURE() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "a frame delay of 0 centiseconds (expected 1 to 65535)");
  }

  GifFlipbook book(8, 6, 10, kBackground);
  book.add(firstFrame());
  const std::vector<std::uint8_t> before = book.bytes();
  EXPECT_THROW(book.add(SplatImage(9, 6, kBlack)), std::invalid_argument);
  EXPECT_THROW(book.add(SplatImage(8, 7, kBlack)), std::invalid_argument);
  EXPECT_THROW(book.add(SplatImage(6, 8, kBlack)), std::invalid_argument);
  EXPECT_EQ(book.frameCount(), 1u);
  EXPECT_EQ(book.bytes(), before);
}

TEST(GifFlipbook, ChoosesTheDelayNearestAFrameRate) {
  EXPECT_EQ(GifFlipbook::delayFor(24.0), 4);
  EXPECT_EQ(GifFlipbook::delayFor(30.0), 3);
  EXPECT_EQ(GifFlipbook::delayFor(25.0), 4);
  EXPECT_EQ(GifFlipbook::delayFor(60.0), 2);   // 1.67, but browsers slow 1 to 10
  EXPECT_EQ(GifFlipbook::delayFor(100.0), 2);  // 1 likewise
  EXPECT_EQ(GifFlipbook::delayFor(10.0), 10);
  EXPECT_EQ(GifFlipbook::delayFor(0.5), 200);
  EXPECT_EQ(GifFlipbook::delayFor(1e-6), 65535);  // the longest a GIF can say
  EXPECT_THROW(GifFlipbook::delayFor(0.0), std::invalid_argument);
  EXPECT_THROW(GifFlipbook::delayFor(-24.0), std::invalid_argument);
  EXPECT_THROW(GifFlipbook::delayFor(std::nan("")), std::invalid_argument);
  EXPECT_THROW(GifFlipbook::delayFor(std::numeric_limits<double>::infinity()),
               std::invalid_argument);
}

class GifFlipbookFile : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("tickfx_gif_" +
            std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()) + "_" +
            std::to_string(::getpid()));
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::filesystem::path dir_;
};

TEST_F(GifFlipbookFile, WritesItsBytes) {
  GifFlipbook book(8, 6, 4, kBackground);
  book.add(firstFrame());
  book.add(secondFrame());
  const std::filesystem::path path = dir_ / "flipbook.gif";
  book.write(path);
  std::ifstream in(path, std::ios::binary);
  const std::vector<std::uint8_t> written{std::istreambuf_iterator<char>(in),
                                          std::istreambuf_iterator<char>()};
  EXPECT_EQ(written, book.bytes());
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir_),
                          std::filesystem::directory_iterator()),
            1);  // no temporary left beside it
}

TEST_F(GifFlipbookFile, RefusesAFolderThatDoesNotExistAndWritesNothing) {
  GifFlipbook book(8, 6, 4, kBackground);
  book.add(firstFrame());
  const std::filesystem::path path = dir_ / "missing" / "flipbook.gif";
  try {
    book.write(path);
    ADD_FAILURE() << "no exception";
  } catch (const WriteError& e) {
    EXPECT_EQ(e.path(), path);
  }
  EXPECT_FALSE(std::filesystem::exists(path));
  EXPECT_FALSE(std::filesystem::exists(dir_ / "missing"));
  EXPECT_TRUE(std::filesystem::is_empty(dir_));
}

}  // namespace
}  // namespace tickfx::preview
