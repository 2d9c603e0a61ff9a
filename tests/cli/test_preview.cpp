// Preview renders: a known scene lands where it must, nearer splats cover farther ones, framing
// keeps every particle in the image, and the PNG bytes do not depend on the thread count.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cstdint>
#include <random>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/preview/ColourMap.h"
#include "app/preview/PinholeCamera.h"
#include "app/preview/PixelFont.h"
#include "app/preview/SplatImage.h"

namespace tickfx::preview {
namespace {

const Rgb kBlack{0, 0, 0}, kRed{255, 0, 0}, kBlue{0, 0, 255};

// A camera on +z, 5 m from the origin, looking at it, y up, 65 × 65 pixels: the origin is the
// centre of pixel (32, 32).
PinholeCamera onPlusZ() {
  return PinholeCamera({0.0, 0.0, 5.0}, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitY(), 40.0, 65,
                       65);
}

Splat splatAt(const PinholeCamera& camera, const Eigen::Vector3d& p, float radius, Rgb colour) {
  const auto q = camera.project(p);
  if (!q) throw std::logic_error("the point is behind the camera");
  return {static_cast<float>(q->x), static_cast<float>(q->y), static_cast<float>(q->depth), radius,
          colour};
}

TEST(PinholeCamera, PutsThePointItLooksAtInTheCentreAndUpAtTheTop) {
  const PinholeCamera camera = onPlusZ();
  const auto origin = camera.project(Eigen::Vector3d::Zero());
  ASSERT_TRUE(origin.has_value());
  EXPECT_DOUBLE_EQ(origin->x, 32.5);
  EXPECT_DOUBLE_EQ(origin->y, 32.5);
  EXPECT_DOUBLE_EQ(origin->depth, 5.0);
  const auto above = camera.project({0.0, 1.0, 0.0});
  const auto right = camera.project({1.0, 0.0, 0.0});
  ASSERT_TRUE(above && right);
  EXPECT_LT(above->y, 32.5);  // up is up the image
  EXPECT_DOUBLE_EQ(above->x, 32.5);
  EXPECT_GT(right->x, 32.5);  // +x is to the right seen from +z
  // tan(20°) · 5 m fills half the image's height: 32.5 pixels.
  EXPECT_NEAR(camera.pixelsPerMetre(5.0), 32.5 / (5.0 * std::tan(20.0 * M_PI / 180.0)), 1e-9);
  EXPECT_FALSE(camera.project({0.0, 0.0, 6.0}).has_value());  // behind
  EXPECT_FALSE(camera.project({0.0, 0.0, 5.0}).has_value());  // at the eye
}

TEST(PinholeCamera, RefusesCamerasThatSeeNothing) {
  const Eigen::Vector3d o = Eigen::Vector3d::Zero(), z{0.0, 0.0, 5.0}, y = Eigen::Vector3d::UnitY();
  EXPECT_THROW(PinholeCamera(z, o, y, 0.0, 10, 10), std::invalid_argument);
  EXPECT_THROW(PinholeCamera(z, o, y, 180.0, 10, 10), std::invalid_argument);
  EXPECT_THROW(PinholeCamera(z, o, y, 40.0, 0, 10), std::invalid_argument);
  EXPECT_THROW(PinholeCamera(o, o, y, 40.0, 10, 10), std::invalid_argument);
  EXPECT_THROW(PinholeCamera(z, o, Eigen::Vector3d::UnitZ(), 40.0, 10, 10), std::invalid_argument);
}

TEST(SplatImage, DrawsAParticleAtTheOriginOnTheCentrePixel) {
  const PinholeCamera camera = onPlusZ();
  SplatImage image(65, 65, kBlack);
  image.draw({splatAt(camera, Eigen::Vector3d::Zero(), 3.0f, kRed)});
  EXPECT_EQ(image.at(32, 32), kRed);
  EXPECT_EQ(image.at(34, 32), kRed);    // inside the radius of 3 pixels
  EXPECT_EQ(image.at(32, 37), kBlack);  // past it and its one-pixel edge
  EXPECT_EQ(image.at(0, 0), kBlack);
  // The edge is blended: a pixel centre 3.2 pixels away is covered 0.3.
  const Rgb edge = image.at(35, 33);  // centre at (35.5, 33.5): √(3² + 1²) ≈ 3.16 from (32.5, 32.5)
  EXPECT_GT(edge[0], 0);
  EXPECT_LT(edge[0], 255);
}

TEST(SplatImage, DrawsNothingBehindTheCamera) {
  const PinholeCamera camera = onPlusZ();
  EXPECT_FALSE(camera.project({0.0, 0.0, 10.0}).has_value());
  SplatImage image(65, 65, kBlack);
  std::vector<Splat> splats;
  for (const Eigen::Vector3d& p :
       {Eigen::Vector3d(0.0, 0.0, 10.0), Eigen::Vector3d(1.0, 1.0, 7.0)}) {
    if (const auto q = camera.project(p))
      splats.push_back({float(q->x), float(q->y), 1.0f, 4.0f, kRed});
  }
  image.draw(splats);
  for (int y = 0; y < 65; ++y) {
    for (int x = 0; x < 65; ++x) ASSERT_EQ(image.at(x, y), kBlack) << x << "," << y;
  }
}

TEST(SplatImage, NearerSplatsCoverFartherOnesInAnyOrder) {
  const PinholeCamera camera = onPlusZ();
  const Splat far = splatAt(camera, Eigen::Vector3d::Zero(), 4.0f, kRed);
  const Splat near = splatAt(camera, {0.0, 0.0, 1.0}, 4.0f, kBlue);
  for (const auto& order : {std::vector{far, near}, std::vector{near, far}}) {
    SplatImage image(65, 65, kBlack);
    image.draw(order);
    EXPECT_EQ(image.at(32, 32), kBlue);
  }
}

std::vector<Eigen::Vector3d> cloud(std::size_t n) {
  std::mt19937 random(7);  // the test's own data: any fixed sequence does
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Eigen::Vector3d> points;
  for (std::size_t i = 0; i < n; ++i)
    points.emplace_back(3.0 * u(random), 1.0 + u(random), u(random));
  return points;
}

TEST(PinholeCamera, FramingKeepsEveryParticleInsideTheImage) {
  const std::vector<Eigen::Vector3d> points = cloud(20000);
  Eigen::Vector3d lo = points[0], hi = points[0];
  for (const auto& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  for (const Eigen::Vector3d& up :
       {Eigen::Vector3d(Eigen::Vector3d::UnitY()), Eigen::Vector3d(Eigen::Vector3d::UnitZ())}) {
    for (const auto& [w, h] : {std::pair{1280, 720}, std::pair{300, 900}}) {
      const PinholeCamera camera = PinholeCamera::framing(lo, hi, up, 40.0, w, h);
      double minX = w, maxX = 0, minY = h, maxY = 0;
      for (const auto& p : points) {
        const auto q = camera.project(p);
        ASSERT_TRUE(q.has_value());
        minX = std::min(minX, q->x), maxX = std::max(maxX, q->x);
        minY = std::min(minY, q->y), maxY = std::max(maxY, q->y);
      }
      EXPECT_GT(minX, 0.0) << w << "x" << h;
      EXPECT_LT(maxX, w);
      EXPECT_GT(minY, 0.0);
      EXPECT_LT(maxY, h);
      // Not lost in the middle either: the cloud spans a good part of the narrower side.
      EXPECT_GT(std::max((maxX - minX) / w, (maxY - minY) / h), 0.4) << w << "x" << h;
    }
  }
}

std::vector<std::uint8_t> renderOn(int threads, const std::vector<Eigen::Vector3d>& points) {
  const PinholeCamera camera =
      PinholeCamera::framing({-3, 0, -1}, {3, 2, 1}, Eigen::Vector3d::UnitY(), 40.0, 320, 180);
  std::vector<Splat> splats;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const auto q = camera.project(points[i]);
    splats.push_back({float(q->x), float(q->y), float(q->depth),
                      float(0.03 * camera.pixelsPerMetre(q->depth)),
                      viridis(static_cast<double>(i) / static_cast<double>(points.size()))});
  }
  SplatImage image(320, 180, {20, 20, 24});
  tbb::task_arena arena(threads);
  arena.execute([&] { image.draw(splats); });
  return image.png();
}

TEST(SplatImage, GivesTheSamePngBytesOnAnyThreadCount) {
  const std::vector<Eigen::Vector3d> points = cloud(50000);
  const std::vector<std::uint8_t> one = renderOn(1, points);
  ASSERT_GT(one.size(), 1000u);
  EXPECT_EQ(std::vector<std::uint8_t>(one.begin(), one.begin() + 8),
            (std::vector<std::uint8_t>{0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'}));
  EXPECT_EQ(renderOn(2, points), one);
  EXPECT_EQ(renderOn(3, points), one);
  EXPECT_EQ(renderOn(1, points), one);  // and across runs
}

TEST(SplatImage, RefusesImagesOfNoOrTooManyPixels) {
  EXPECT_THROW(SplatImage(0, 10, kBlack), std::invalid_argument);
  EXPECT_THROW(SplatImage(10, 1000000, kBlack), std::invalid_argument);
  try {
    SplatImage(0, 720, kBlack);
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "an image of 0x720 pixels (expected 1 to 16384 a side)");
  }
}

// The pixels an image holds of `colour`, as "x,y" in row order.
std::vector<std::pair<int, int>> inked(const SplatImage& image, Rgb colour) {
  std::vector<std::pair<int, int>> out;
  for (int y = 0; y < image.height(); ++y) {
    for (int x = 0; x < image.width(); ++x) {
      if (image.at(x, y) == colour) out.emplace_back(x, y);
    }
  }
  return out;
}

TEST(PixelFont, DrawsEachGlyphsPixelsAtItsScale) {
  const Rgb white{255, 255, 255};
  SplatImage one(12, 8, kBlack);
  drawText(one, 0, 0, "1", white, 1);
  // "1": the stem down the middle, a flag to its left, a foot three wide.
  const std::vector<std::pair<int, int>> expected = {{2, 0}, {1, 1}, {2, 1}, {2, 2}, {2, 3},
                                                     {2, 4}, {2, 5}, {1, 6}, {2, 6}, {3, 6}};
  EXPECT_EQ(inked(one, white), expected);
  // Scale 2: each font pixel a 2 × 2 square, the glyph's top pixel at (4..5, 0..1).
  SplatImage two(24, 16, kBlack);
  drawText(two, 0, 0, "1", white, 2);
  EXPECT_EQ(inked(two, white).size(), 4 * expected.size());
  EXPECT_EQ(two.at(4, 0), white);
  EXPECT_EQ(two.at(5, 1), white);
  EXPECT_EQ(two.at(3, 0), kBlack);
  // Upper case as lower case, anything unknown as '?', pixels past the edge skipped.
  SplatImage upper(40, 8, kBlack), lower(40, 8, kBlack), unknown(6, 8, kBlack),
      question(6, 8, kBlack);
  drawText(upper, 0, 0, "FRAME", white, 1);
  drawText(lower, 0, 0, "frame", white, 1);
  EXPECT_EQ(inked(upper, white), inked(lower, white));
  drawText(unknown, 0, 0, "~", white, 1);
  drawText(question, 0, 0, "?", white, 1);
  EXPECT_EQ(inked(unknown, white), inked(question, white));
  EXPECT_FALSE(inked(question, white).empty());
  // Every character the font has is a pattern of its own (names in captions may quote or
  // bracket), and none is the '?' of an unknown one but '?' itself.
  const std::string known = " !\"#'()*+,-./0123456789:;<=>?[]_%abcdefghijklmnopqrstuvwxyz";
  std::set<std::vector<std::pair<int, int>>> patterns;
  for (const char c : known) {
    SplatImage glyph(6, 8, kBlack);
    drawText(glyph, 0, 0, std::string(1, c), white, 1);
    patterns.insert(inked(glyph, white));
  }
  EXPECT_EQ(patterns.size(), known.size());
  SplatImage edge(3, 3, kBlack);
  drawText(edge, -2, -2, "88", white, 1);  // partly outside: no crash, some ink
  EXPECT_FALSE(inked(edge, white).empty());
  EXPECT_EQ(textWidth("abc", 2), 34);
  EXPECT_EQ(textWidth("", 2), 0);
}

TEST(Viridis, RunsFromDarkPurpleToYellow) {
  EXPECT_EQ(viridis(0.0), (Rgb{68, 1, 84}));
  EXPECT_EQ(viridis(1.0), (Rgb{253, 231, 37}));
  EXPECT_EQ(viridis(0.5), (Rgb{33, 144, 141}));
  EXPECT_EQ(viridis(-3.0), viridis(0.0));
  EXPECT_EQ(viridis(7.0), viridis(1.0));
  EXPECT_EQ(viridis(std::nan("")), viridis(0.0));
  // Brighter all the way (the map's lightness rises monotonically).
  double last = -1.0;
  for (int i = 0; i <= 64; ++i) {
    const Rgb c = viridis(i / 64.0);
    const double luma = 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
    EXPECT_GT(luma, last) << i;
    last = luma;
  }
}

}  // namespace
}  // namespace tickfx::preview
