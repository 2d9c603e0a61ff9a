// What a preview draws around and from the particles: lines and their clipping, the ground grid,
// colouring by a value or by Cd, splat sizes from pscale, springs as lines, and cache folders.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/FrameTimes.h"
#include "app/preview/ColourBy.h"
#include "app/preview/ColourMap.h"
#include "app/preview/FrameRenderer.h"
#include "app/preview/PinholeCamera.h"
#include "app/preview/SceneGuides.h"
#include "app/preview/SplatImage.h"
#include "io/cache/CacheFolder.h"
#include "io/cache/CsvCache.h"
#include "io/cache/PlyCache.h"
#include "io/effect/EffectBuilder.h"
#include "io/effect/EffectParser.h"
#include "particles/ParticleSystem.h"

namespace tickfx::preview {

using namespace io;  // the frames and caches a preview reads
namespace {

namespace fs = std::filesystem;

const Rgb kBlack{0, 0, 0}, kRed{255, 0, 0}, kWhite{255, 255, 255};

// A camera on +z, 5 m from the origin, looking at it, y up, 65 × 65 pixels: the origin is the
// centre of pixel (32, 32).
PinholeCamera onPlusZ() {
  return PinholeCamera({0.0, 0.0, 5.0}, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitY(), 40.0, 65,
                       65);
}

// A frame of particles at `points`, ids 0, 1, ..., at rest, age 1 s of a 4 s life, mass 2 kg.
FrameData frameAt(const std::vector<Eigen::Vector3d>& points,
                  const std::vector<std::string>& attributes = {}) {
  FrameData f;
  f.resize(points.size(), attributes);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const auto r = static_cast<Eigen::Index>(i);
    f.id[i] = i;
    for (int c = 0; c < 3; ++c) {
      f.position[c][r] = static_cast<float>(points[i][c]);
      f.velocity[c][r] = 0.0f;
    }
    f.age[r] = 1.0f;
    f.life[r] = 4.0f;
    f.mass[r] = 2.0f;
  }
  return f;
}

TEST(SplatImage, DrawsALineAcrossThePixelsItPasses) {
  SplatImage image(32, 16, kBlack);
  image.drawLine(2.0, 8.5, 20.0, 8.5, kWhite, 1.0f);  // along the centres of row 8
  for (int x = 2; x < 20; ++x) EXPECT_EQ(image.at(x, 8), kWhite) << x;
  EXPECT_EQ(image.at(1, 8), kBlack);
  EXPECT_EQ(image.at(21, 8), kBlack);
  EXPECT_EQ(image.at(10, 7), kBlack);
  EXPECT_EQ(image.at(10, 9), kBlack);
  // Between two rows: each takes half.
  image.drawLine(0.0, 3.0, 31.0, 3.0, kWhite, 1.0f);
  EXPECT_EQ(image.at(10, 2), (Rgb{128, 128, 128}));
  EXPECT_EQ(image.at(10, 3), (Rgb{128, 128, 128}));
  // Steep lines walk the rows; a line wholly outside, or through infinity, draws nothing.
  SplatImage steep(16, 16, kBlack);
  steep.drawLine(4.5, 0.0, 4.5, 16.0, kRed, 1.0f);
  for (int y = 0; y < 16; ++y) EXPECT_EQ(steep.at(4, y), kRed) << y;
  SplatImage untouched(16, 16, kBlack);
  untouched.drawLine(-50.0, -5.0, -1.0, -9.0, kRed, 1.0f);
  untouched.drawLine(1e12, 3.0, 2e12, 3.0, kRed, 1.0f);
  untouched.drawLine(0.0, 0.0, std::numeric_limits<double>::infinity(), 9.0, kRed, 1.0f);
  for (int y = 0; y < 16; ++y) {
    for (int x = 0; x < 16; ++x) ASSERT_EQ(untouched.at(x, y), kBlack);
  }
}

TEST(PinholeCamera, CutsASegmentWhereItPassesBehindTheCamera) {
  const PinholeCamera camera = onPlusZ();
  EXPECT_FALSE(camera.projectSegment({0, 0, 6}, {1, 0, 9}).has_value());  // wholly behind
  const auto both = camera.projectSegment({-1, 0, 0}, {1, 0, 0});
  ASSERT_TRUE(both.has_value());
  EXPECT_NEAR(both->first.depth, 5.0, 1e-12);
  // From the origin to behind the camera: the visible part ends just past the near plane.
  const auto cut = camera.projectSegment({0, -1, 0}, {0, -1, 10});
  ASSERT_TRUE(cut.has_value());
  EXPECT_NEAR(cut->first.depth, 5.0, 1e-12);
  EXPECT_NEAR(cut->second.depth, 2.0 * PinholeCamera::kNear, 1e-12);
  EXPECT_GT(cut->second.y, 1e3);  // far below the image: the line runs down off it
}

TEST(GroundGrid, CoversTheFootprintInWholeMetresAndCoarsensWhenWide) {
  GroundGrid g = *GroundGrid::under({-2.5, 0.0, -1.0}, {3.2, 5.0, 4.0}, UpAxis::Y);
  EXPECT_EQ(g.spacing, 1.0);
  EXPECT_EQ(g.lo, Eigen::Vector2d(-4.0, -2.0));  // x and z, rounded out, one more
  EXPECT_EQ(g.hi, Eigen::Vector2d(5.0, 5.0));
  g = *GroundGrid::under({-1.0, 0.5, 7.0}, {1.0, 2.0, 9.0}, UpAxis::Z);  // x and y
  EXPECT_EQ(g.lo, Eigen::Vector2d(-2.0, -1.0));
  EXPECT_EQ(g.hi, Eigen::Vector2d(2.0, 3.0));
  g = *GroundGrid::under({0.0, 0.0, 0.0}, {1000.0, 1.0, 10.0}, UpAxis::Y);
  EXPECT_EQ(g.spacing, 100.0);
  EXPECT_EQ(g.hi.x(), 1100.0);
  // A run that blew up: no grid rather than 10²⁰ lines.
  EXPECT_FALSE(GroundGrid::under({0.0, 0.0, 0.0}, {1e30, 1.0, 1.0}, UpAxis::Y).has_value());
  EXPECT_TRUE(GroundGrid::under({0.0, 0.0, 0.0}, {9e13, 1.0, 1.0}, UpAxis::Y).has_value());
}

TEST(GroundGrid, DrawsItsLinesOnTheGroundAsSeenFromAbove) {
  // Looking straight down at the origin from 10 m, z up the image: lines at whole metres.
  const PinholeCamera camera({0.5, 10.0, 0.5}, {0.5, 0.0, 0.5}, -Eigen::Vector3d::UnitZ(), 40.0,
                             101, 101);
  SplatImage image(101, 101, kBlack);
  drawGroundGrid(image, camera, *GroundGrid::under({-1, 0, -1}, {1, 0, 1}, UpAxis::Y));
  const auto origin = camera.project({0.0, 0.0, 0.0});
  const auto between = camera.project({0.5, 0.0, 0.5});
  ASSERT_TRUE(origin && between);
  EXPECT_NE(image.at(static_cast<int>(origin->x), static_cast<int>(between->y)), kBlack);
  EXPECT_EQ(image.at(static_cast<int>(between->x), static_cast<int>(between->y)), kBlack);
}

TEST(ColourBy, ComputesEachValueAndRefusesWhatTheFrameLacks) {
  FrameData f = frameAt({{0, 0, 0}, {1, 0, 0}}, {"pscale"});
  f.velocity.x[0] = 3.0f;
  f.velocity.y[0] = 4.0f;
  f.life[1] = std::numeric_limits<float>::infinity();
  f.attributes[0] << 0.25f, 0.5f;
  EXPECT_EQ(ColourBy::parse("speed", f).values(f), (std::vector<double>{5.0, 0.0}));
  EXPECT_EQ(ColourBy::parse("nage", f).values(f), (std::vector<double>{0.25, 0.0}));  // immortal: 0
  EXPECT_EQ(ColourBy::parse("id", f).values(f), (std::vector<double>{0.0, 1.0}));
  EXPECT_EQ(ColourBy::parse("mass", f).values(f), (std::vector<double>{2.0, 2.0}));
  EXPECT_EQ(ColourBy::parse("pscale", f).values(f), (std::vector<double>{0.25, 0.5}));
  EXPECT_EQ(ColourBy::parse("pscale", f).title(), "pscale (m)");
  const std::vector<Rgb> c = ColourBy::parse("speed", f).colours(f, 0.0, 5.0);
  EXPECT_EQ(c[0], viridis(1.0));
  EXPECT_EQ(c[1], viridis(0.0));
  try {
    ColourBy::parse("Cd", f);
    ADD_FAILURE() << "Cd accepted without Cd_r, Cd_g, Cd_b";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "'Cd' (expected speed, age, nage, id, life, mass or pscale)");
  }
}

TEST(ColourBy, TakesTheParticlesOwnCd) {
  FrameData f = frameAt({{0, 0, 0}, {1, 0, 0}}, {"Cd_r", "Cd_g", "Cd_b"});
  f.attributes[0] << 1.0f, 0.0f;
  f.attributes[1] << 0.5f, 2.0f;                                     // held to 1
  f.attributes[2] << 0.0f, std::numeric_limits<float>::quiet_NaN();  // NaN: 0
  const ColourBy cd = ColourBy::parse("Cd", f);
  EXPECT_TRUE(cd.ownColours());
  EXPECT_EQ(cd.colours(f, 0.0, 1.0), (std::vector<Rgb>{{255, 128, 0}, {0, 255, 0}}));
  EXPECT_EQ(ColourBy::choices(f).back(), "Cd");
}

TEST(FrameRenderer, SizesSplatsByPscaleInMetres) {
  const PinholeCamera camera = onPlusZ();
  const double pixelsPerMetre = camera.pixelsPerMetre(5.0);  // about 17.9
  FrameData f = frameAt({{0, 0, 0}}, {"pscale"});
  f.attributes[0][0] = 0.5f;  // a radius of about 8.9 pixels
  RenderSettings settings;
  settings.background = kBlack;
  const SplatImage image = renderFrame(camera, f, {kRed}, {}, settings);
  const int reach = static_cast<int>(0.5 * pixelsPerMetre);
  EXPECT_EQ(image.at(32 + reach - 1, 32), kRed);
  EXPECT_EQ(image.at(32 + reach + 2, 32), kBlack);
  // Without pscale the same size comes from --radius; ignoring pscale gives the pixel size.
  settings.size.ignorePscale = true;
  const SplatImage small = renderFrame(camera, f, {kRed}, {}, settings);
  EXPECT_EQ(small.at(32 + reach - 1, 32), kBlack);
  settings.size.radiusMetres = 0.5;
  EXPECT_EQ(renderFrame(camera, f, {kRed}, {}, settings).png(), image.png());
}

TEST(FrameRenderer, DrawsSpringsAsLinesBetweenTheirEnds) {
  const PinholeCamera camera = onPlusZ();
  const FrameData f = frameAt({{-1, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  RenderSettings settings;
  settings.background = kBlack;
  settings.lineColour = kWhite;
  const std::vector<Rgb> colours(3, kRed);
  // Ids 0 and 1 joined; a pair naming id 9, not in the frame, is passed over.
  const SplatImage image = renderFrame(camera, f, colours, {{0, 1}, {2, 9}}, settings);
  EXPECT_NE(image.at(20, 32), kBlack);  // on the line, between the two splats
  EXPECT_EQ(image.at(32, 26), kBlack);  // between (0, 0, 0) and (0, 1, 0): no spring there
  EXPECT_THROW(renderFrame(camera, f, {kRed}, {}, settings), std::invalid_argument);
}

// Every particle of every frame of each sample lands inside the image of the camera framed on the
// whole run, at the preview's default size and at a tall one.
TEST(PinholeCamera, FramingASampleKeepsEveryParticleOfEveryFrameInside) {
  for (const char* sample : {"fountain.toml", "flag.toml", "burst.toml"}) {
    const LoadResult load = loadEffectFile(fs::path(TICKFX_SOURCE_DIR) / "samples" / sample);
    ASSERT_TRUE(load.ok()) << sample;
    std::vector<Eigen::Vector3d> points;
    const auto system = buildOfflineSystem(*load.effect, std::nullopt);
    app::FrameSchedule schedule = app::FrameSchedule::fixedRate(
        load.effect->output.fps,
        app::lengthOfFrames(load.effect->output.fps, load.effect->output.frameCount(), "length"));
    while (const auto d = schedule.next()) {
      system->advance(*d);
      const FrameData f = captureFrame(*system, schedule.framesDone(), 0.0);
      for (Eigen::Index r = 0; r < f.position.x.size(); ++r) {
        points.emplace_back(f.position.x[r], f.position.y[r], f.position.z[r]);
      }
    }
    ASSERT_GT(points.size(), 1000u) << sample;
    Eigen::Vector3d lo = points[0], hi = points[0];
    for (const auto& p : points) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    for (const auto& [w, h] : {std::pair{1280, 720}, std::pair{300, 900}}) {
      const PinholeCamera camera =
          PinholeCamera::framing(lo, hi, Eigen::Vector3d::UnitY(), 40.0, w, h, 0.1);
      for (const auto& p : points) {
        const auto q = camera.project(p);
        ASSERT_TRUE(q.has_value()) << sample;
        ASSERT_TRUE(q->x > 0.0 && q->x < w && q->y > 0.0 && q->y < h)
            << sample << " " << w << "x" << h << ": (" << q->x << ", " << q->y << ")";
      }
    }
  }
}

class CacheFolderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("tickfx_cache_folder_" +
            std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_F(CacheFolderTest, ListsFramesInOrderAndReadsEachFromOneFile) {
  FrameData a = frameAt({{1, 2, 3}});
  a.timeSeconds = 0.5;
  writePlyCache(a, dir_ / "frame_0012.ply");
  writeCsvCache(frameAt({{4, 5, 6}}), dir_ / "frame_0012.csv");  // the PLY wins
  writeCsvCache(frameAt({{7, 8, 9}, {0, 0, 0}}), dir_ / "frame_0003.csv");
  std::ofstream(dir_ / "frame_x.csv") << "not a frame";
  std::ofstream(dir_ / "notes.txt") << "not a frame";
  const std::vector<CacheFrameFile> files = listCacheFrames(dir_);
  ASSERT_EQ(files.size(), 2u);
  EXPECT_EQ(files[0].frame, 3);
  EXPECT_EQ(files[1].frame, 12);
  EXPECT_EQ(files[1].path.filename(), "frame_0012.ply");
  const FrameData read = readCacheFrame(files[1]);
  EXPECT_EQ(read.frame, 12);
  EXPECT_EQ(read.position.x[0], 1.0f);
  EXPECT_EQ(read.timeSeconds, 0.5);
  EXPECT_EQ(readCacheFrame(files[0]).size(), 2u);
}

TEST_F(CacheFolderTest, RefusesAFolderWithoutFrames) {
  std::ofstream(dir_ / "frame_0001.txt") << "x";
  try {
    listCacheFrames(dir_);
    ADD_FAILURE() << "no frames, no error";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), dir_.string() +
                                         ": error: no frame caches here (expected frame_0001.vdb, "
                                         ".ply or .csv, as tickfx run writes them)");
  }
  EXPECT_THROW(listCacheFrames(dir_ / "absent"), std::runtime_error);
}

}  // namespace
}  // namespace tickfx::preview
