// What `tickfx preview` shows, read back pixel by pixel: a hand-made cache of a red, a green and
// a blue particle at known positions, seen by a known camera, must put those colours where the
// camera projects them and the background everywhere else.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "CliTestSupport.h"
#include "DecodedPng.h"
#include "app/preview/FrameRenderer.h"
#include "app/preview/PinholeCamera.h"
#include "io/cache/CsvCache.h"
#include "io/cache/FrameData.h"

namespace tickfx::cli_test {
namespace {

namespace fs = std::filesystem;

class PreviewPixels : public CliFixture {
 protected:
  PreviewPixels() : CliFixture("tickfx_preview_pixels") {}
  Result run(const std::string& args) const { return runProgram(TICKFX_CLI, args); }
};

struct Particle {
  Eigen::Vector3d position;
  std::array<int, 3> colour;
};

// One frame of a CSV cache, written by the cache writer `tickfx run` uses, with Houdini's Cd.
void writeCache(const fs::path& dir, const std::vector<Particle>& particles) {
  fs::create_directories(dir);
  io::FrameData frame;
  frame.resize(particles.size(), {"Cd_r", "Cd_g", "Cd_b"});
  for (std::size_t i = 0; i < particles.size(); ++i) {
    const auto r = static_cast<Eigen::Index>(i);
    frame.id[i] = i;
    for (int c = 0; c < 3; ++c) {
      frame.position[c][r] = static_cast<float>(particles[i].position[c]);
      frame.velocity[c][r] = 0.0f;
      frame.attributes[static_cast<std::size_t>(c)][r] =
          static_cast<float>(particles[i].colour[c]) / 255.0f;
    }
    frame.age[r] = 0.5f;
    frame.life[r] = 2.0f;
    frame.mass[r] = 1.0f;
  }
  io::writeCsvCache(frame, dir / "frame_0001.csv");
}

TEST_F(PreviewPixels, ShowsEachParticleInItsOwnColourWhereTheCameraProjectsIt) {
  const std::vector<Particle> particles = {{{0.0, 0.0, 0.0}, {255, 0, 0}},
                                           {{1.5, 0.5, 0.0}, {0, 255, 0}},
                                           {{-1.0, -1.0, 0.5}, {0, 0, 255}}};
  writeCache(dir_ / "cache", particles);
  const Result r = run("preview " + path("cache") +
                       " --camera 0,0,8 --lookat 0,0,0 --fov 40 --size 200x150 --point-size 9"
                       " --no-guides --out " +
                       path("png"));
  ASSERT_EQ(r.exit, 0) << r.err;
  const test::DecodedPng png = test::decodePng(readAll(path("png/frame_0001.png")));
  ASSERT_EQ(png.error, "");
  ASSERT_EQ(png.width, 200);
  ASSERT_EQ(png.height, 150);

  const preview::PinholeCamera camera({0.0, 0.0, 8.0}, {0.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, 40.0, 200,
                                      150);
  const preview::Rgb background = preview::RenderSettings{}.background;
  const std::array<int, 3> bg = {background[0], background[1], background[2]};
  std::vector<std::array<int, 2>> centres;
  for (const Particle& p : particles) {
    const auto at = camera.project(p.position);
    ASSERT_TRUE(at.has_value());
    const int x = static_cast<int>(at->x), y = static_cast<int>(at->y);
    ASSERT_TRUE(x >= 0 && x < 200 && y >= 0 && y < 150);
    centres.push_back({x, y});
    // The splat's centre is the particle's own colour, whole.
    EXPECT_EQ(png.at(x, y), p.colour)
        << "particle at " << p.position.transpose() << ", pixel " << x << "," << y;
  }
  // The particles are apart on the screen: none draws over another's centre.
  ASSERT_NE(centres[0], centres[1]);
  ASSERT_NE(centres[0], centres[2]);

  // Away from the splats (more than their radius and a pixel of soft edge) every pixel is the
  // background (--no-guides: no grid, axes or legend), but for the caption band along the top
  // (the source, frame and particle count, drawn on a strip of its own).
  int drawn = 0, stray = 0;
  for (int y = 0; y < 150; ++y) {
    for (int x = 0; x < 200; ++x) {
      bool near = false;
      for (const auto& c : centres) {
        near = near || (std::abs(x - c[0]) <= 7 && std::abs(y - c[1]) <= 7);
      }
      const bool isBackground = png.at(x, y) == bg;
      if (near && !isBackground) ++drawn;
      if (!near && !isBackground && y >= 16) ++stray;
    }
  }
  EXPECT_EQ(stray, 0) << "pixels drawn away from every particle";
  // Three splats of 9 px: each covers at least its inner 7×7 square.
  EXPECT_GE(drawn, 3 * 49);
}

}  // namespace
}  // namespace tickfx::cli_test
