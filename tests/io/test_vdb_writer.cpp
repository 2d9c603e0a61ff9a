// The parallel encoder of VDB point caches (io/cache/VdbPointsEncoder) against OpenVDB's own
// serial writer: the same bytes for every option and size, on any number of threads, and files
// that read back (through tickfx and through OpenVDB alone) to the points written.
#include <gtest/gtest.h>
#include <tbb/global_control.h>
#include <tbb/task_arena.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "FileSizeLimit.h"
#include "PointCacheTestSupport.h"
#include "Sanitized.h"
#include "VdbTestData.h"
#include "io/cache/FrameData.h"
#include "io/cache/VdbCacheOptions.h"
#include "io/cache/VdbPointCache.h"
#include "io/cache/VdbPointCacheBytes.h"
#include "particles/Isa.h"
#include "tests/support/FileBytes.h"

namespace tickfx::io {
namespace {

namespace fs = std::filesystem;
namespace vdbt = tickfx::vdb_test;
using detail::VdbEncoder;
using detail::VdbGrouping;
using test::fileBytes;

constexpr VdbCacheOptions kDefault{};
constexpr VdbCacheOptions kFixed16{VdbCacheOptions::Compression::None,
                                   VdbCacheOptions::Positions::Fixed16};
constexpr VdbCacheOptions kBlosc{VdbCacheOptions::Compression::Blosc};
constexpr VdbCacheOptions kFixed16Blosc{VdbCacheOptions::Compression::Blosc,
                                        VdbCacheOptions::Positions::Fixed16};
// The thread counts each encoding runs under: one, the bench's two, an odd count, more than
// the machine may have. A sanitizer build runs one and three: the serial and the split paths, an
// uneven split included, at half the cost (each encoding takes seconds there).
constexpr std::array<int, 4> kReleaseThreads{1, 2, 3, 8};
constexpr std::array<int, 2> kSanitizedThreads{1, 3};
constexpr std::span<const int> kThreads = tickfx::test::kSanitized
                                              ? std::span<const int>(kSanitizedThreads)
                                              : std::span<const int>(kReleaseThreads);
// The most of them: an arena may have more threads than the machine has cores only below TBB's
// global limit, raised to this where they run.
constexpr std::size_t kMostThreads =
    static_cast<std::size_t>(*std::max_element(kThreads.begin(), kThreads.end()));

std::uint32_t bits(float x) { return std::bit_cast<std::uint32_t>(x); }

VdbCacheMetadata metadata() {
  return VdbCacheMetadata{"fedcba9876543210", 77, 120, "semi_implicit_euler", "0.1.0"};
}

// A pure function of (i, c) in [0, 1): splitmix64's finaliser, its top 24 bits.
float unit(std::uint64_t i, std::uint64_t c) {
  std::uint64_t z = i * 0x9e3779b97f4a7c15ULL + c * 0xbf58476d1ce4e5b9ULL + 0x2545f4914f6cdd1dULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  z ^= z >> 31;
  return static_cast<float>(z >> 40) * 0x1p-24f;
}

// n particles in a box of `half` metres either side of 0 (so about (half / 4)³ leaves when dense
// enough), ids 5, 7, 9, ... (rows in id order, as FrameData promises), every standard column
// varying, and the custom attributes `names` (whole numbers for an int attribute).
FrameData frameOf(std::size_t n, float half, const std::vector<std::string>& names = {}) {
  FrameData f;
  f.resize(n, names);
  f.frame = 12;
  f.timeSeconds = 0.5;
  for (std::size_t k = 0; k < n; ++k) {
    const auto i = static_cast<Eigen::Index>(k);
    f.id[k] = 2 * k + 5;
    for (int c = 0; c < 3; ++c) {
      const auto cc = static_cast<std::uint64_t>(c);
      f.position[c][i] = half * (2.0f * unit(k, cc) - 1.0f);
      f.velocity[c][i] = 3.0f * unit(k, 3 + cc) - 1.5f;
    }
    f.age[i] = unit(k, 6);
    f.life[i] = k % 3 == 0 ? std::numeric_limits<float>::infinity() : 1.0f + unit(k, 7);
    f.mass[i] = 0.5f + unit(k, 8);
    for (std::size_t a = 0; a < names.size(); ++a) {
      const float u = unit(k, 9 + a);
      f.attributes[a][i] = names[a] == "hitnum" ? std::floor(100.0f * u) : u;
    }
  }
  return f;
}

// Where two byte strings first differ (or the shorter one's length), for a failure's message.
std::size_t firstDifference(const std::string& a, const std::string& b) {
  const auto [ia, ib] = std::mismatch(
      a.begin(), a.begin() + static_cast<std::ptrdiff_t>(std::min(a.size(), b.size())), b.begin());
  return static_cast<std::size_t>(ia - a.begin());
}

class ioVdbWriter : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("tickfx_vdb_writer_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // The parallel encoder's bytes, and the file writeVdbPointCache writes, under each of
  // kThreads, are the serial writer's bytes; the file reads back to `frame` (positions exactly,
  // or within Fixed16's step) through tickfx and holds its points for OpenVDB alone.
  void expectSameBytesAsOpenVdb(const FrameData& frame, const VdbCacheOptions& options) {
    const std::string serial =
        detail::vdbPointCacheBytes(frame, metadata(), options, VdbEncoder::Serial);
    ASSERT_GT(serial.size(), 100u);
    const tbb::global_control allowed(tbb::global_control::max_allowed_parallelism, kMostThreads);
    for (const int threads : kThreads) {
      SCOPED_TRACE(std::to_string(threads) + " threads");
      tbb::task_arena arena(threads);
      std::string parallel;
      const fs::path file = dir_ / ("t" + std::to_string(threads) + ".vdb");
      arena.execute([&] {
        parallel = detail::vdbPointCacheBytes(frame, metadata(), options, VdbEncoder::Parallel);
        writeVdbPointCache(frame, metadata(), file, options);
      });
      EXPECT_EQ(parallel.size(), serial.size());
      EXPECT_TRUE(parallel == serial)
          << "the encoders differ first at byte " << firstDifference(parallel, serial) << " of "
          << serial.size();
      const std::string written = fileBytes(file);
      EXPECT_TRUE(written == serial)
          << "the file differs first at byte " << firstDifference(written, serial);
      if (threads == kThreads[0]) expectReadsBack(file, frame, options);
    }
  }

  static void expectReadsBack(const fs::path& file, const FrameData& frame,
                              const VdbCacheOptions& options) {
    const FrameData back = readVdbPointCache(file);
    ASSERT_EQ(back.size(), frame.size());
    EXPECT_EQ(back.id, frame.id);
    EXPECT_EQ(back.frame, frame.frame);
    EXPECT_EQ(back.attributeNames, frame.attributeNames);
    const bool fixed16 = options.positions == VdbCacheOptions::Positions::Fixed16;
    std::size_t wrong = 0;
    for (Eigen::Index i = 0; i < static_cast<Eigen::Index>(frame.size()); ++i) {
      for (int c = 0; c < 3; ++c) {
        const float want = frame.position[c][i], got = back.position[c][i];
        wrong += fixed16 ? !(std::abs(got - want) <= 2e-5f * (1.0f + std::abs(want)))
                         : bits(got) != bits(want);
        wrong += bits(back.velocity[c][i]) != bits(frame.velocity[c][i]);
      }
      wrong += bits(back.age[i]) != bits(frame.age[i]);
      wrong += bits(back.life[i]) != bits(frame.life[i]);
      wrong += bits(back.mass[i]) != bits(frame.mass[i]);
      for (std::size_t a = 0; a < frame.attributes.size(); ++a)
        wrong += bits(back.attributes[a][i]) != bits(frame.attributes[a][i]);
    }
    EXPECT_EQ(wrong, 0u) << "values that did not read back";
    const vdbt::PointsGridRead grid = vdbt::readPointsGrid(file, "points");
    EXPECT_EQ(grid.pointCount, frame.size());
    EXPECT_EQ(grid.points.size(), frame.size());
  }

  fs::path dir_;
};

TEST_F(ioVdbWriter, DefaultOptionsGiveOpenVdbsBytes) {
  expectSameBytesAsOpenVdb(frameOf(20000, 40.0f), kDefault);
}

TEST_F(ioVdbWriter, Fixed16PositionsGiveOpenVdbsBytes) {
  expectSameBytesAsOpenVdb(frameOf(20000, 40.0f), kFixed16);
}

TEST_F(ioVdbWriter, BloscGivesOpenVdbsBytes) {
  expectSameBytesAsOpenVdb(frameOf(20000, 40.0f), kBlosc);
}

TEST_F(ioVdbWriter, Fixed16WithBloscGivesOpenVdbsBytes) {
  expectSameBytesAsOpenVdb(frameOf(20000, 40.0f), kFixed16Blosc);
}

// No leaf: OpenVDB's pass count 0, nothing else (written by OpenVDB alone, see encodePointsFile).
TEST_F(ioVdbWriter, AnEmptyFrameGivesOpenVdbsBytes) {
  for (const VdbCacheOptions& options : {kDefault, kFixed16Blosc}) {
    const FrameData empty = frameOf(0, 1.0f);
    expectSameBytesAsOpenVdb(empty, options);
  }
}

// One leaf of one point: the descriptor and the page of every attribute in one piece each.
TEST_F(ioVdbWriter, OnePointGivesOpenVdbsBytes) {
  for (const VdbCacheOptions& options : {kDefault, kFixed16, kBlosc, kFixed16Blosc})
    expectSameBytesAsOpenVdb(test::onePointFrame(), options);
}

// Every kind of custom attribute (float, int, vec3) after the standard ones.
TEST_F(ioVdbWriter, CustomAttributesGiveOpenVdbsBytes) {
  const FrameData frame = frameOf(30000, 30.0f, {"heat", "hitnum", "Cd_r", "Cd_g", "Cd_b", "w"});
  for (const VdbCacheOptions& options : {kDefault, kBlosc})
    expectSameBytesAsOpenVdb(frame, options);
}

// 10⁶ points over a 100 m box (about 2700 leaves, hundreds of leaf ranges): with blosc every
// attribute takes several 1 MiB pages, each gathering the arrays of many leaves. A sanitizer build
// writes 300 000 (each float array still over a 1 MiB page, each vector one over three): the same
// paths, at a quarter of the minute 10⁶ took there.
TEST_F(ioVdbWriter, AMillionPointsGiveOpenVdbsBytes) {
  const FrameData frame = frameOf(tickfx::test::kSanitized ? 300000 : 1000000, 50.0f);
  for (const VdbCacheOptions& options : {kDefault, kBlosc})
    expectSameBytesAsOpenVdb(frame, options);
}

// Buffers of one frame kept for the next (FileBytes): a frame written after a larger one with
// other values and attributes, into the blocks that frame left, gives its own bytes, not any of
// the larger frame's; and so does the larger frame written again after it.
TEST_F(ioVdbWriter, KeptBuffersGiveEachFramesOwnBytes) {
  const FrameData large = frameOf(600000, 40.0f, {"heat", "hitnum"});
  FrameData small = frameOf(540000, 40.0f, {"heat", "hitnum"});
  for (Eigen::Index i = 0; i < static_cast<Eigen::Index>(small.size()); ++i) {
    small.velocity[0][i] = -small.velocity[0][i];
    small.attributes[0][i] += 1.0f;
  }
  const std::string largeBytes =
      detail::vdbPointCacheBytes(large, metadata(), kDefault, VdbEncoder::Serial);
  const std::string smallBytes =
      detail::vdbPointCacheBytes(small, metadata(), kDefault, VdbEncoder::Serial);
  for (int round = 0; round < 2; ++round) {
    SCOPED_TRACE("round " + std::to_string(round));
    EXPECT_TRUE(detail::vdbPointCacheBytes(large, metadata(), kDefault, VdbEncoder::Parallel) ==
                largeBytes);
    const std::string again =
        detail::vdbPointCacheBytes(small, metadata(), kDefault, VdbEncoder::Parallel);
    EXPECT_EQ(again.size(), smallBytes.size());
    EXPECT_TRUE(again == smallBytes)
        << "the encoders differ first at byte " << firstDifference(again, smallBytes);
  }
}

// Leaves in several of the tree's top nodes (4096 m apart), whose order in the tree is not the
// leaves' Coord order: the attributes' placeholders go on the tree's first leaf, and the others,
// which hold none, still count every attribute in the file's memory statistics.
TEST_F(ioVdbWriter, LeavesFarApartGiveOpenVdbsBytes) {
  FrameData frame = frameOf(20000, 40.0f);
  for (Eigen::Index i = 0; i < static_cast<Eigen::Index>(frame.size()); ++i) {
    const float shift = i % 3 == 0 ? 0.0f : i % 3 == 1 ? 5000.0f : -9000.0f;
    frame.position[0][i] -= shift;
    frame.position[1][i] += shift;
  }
  for (const VdbCacheOptions& options : {kDefault, kFixed16Blosc})
    expectSameBytesAsOpenVdb(frame, options);
}

// 2·10⁵ of 2.2·10⁵ points in one 8 m leaf, the others over an 80 m box: that leaf's P, v and id
// arrays are larger than a page (pages of their own, closing the page before them), its float
// arrays fill most of one, in both position encodings; without blosc, they are stored into place
// as one stretch of 2.4 MB (P) or 0.8 MB (each float).
TEST_F(ioVdbWriter, ArraysLargerThanAPageGiveOpenVdbsBytes) {
  FrameData frame = frameOf(220000, 40.0f);
  for (Eigen::Index i = 0; i < static_cast<Eigen::Index>(frame.size()); ++i) {
    if (i % 11 == 0) continue;
    for (int c = 0; c < 3; ++c) frame.position[c][i] = 4.0f + frame.position[c][i] * (3.4f / 40.0f);
  }
  for (const VdbCacheOptions& options : {kDefault, kFixed16, kBlosc, kFixed16Blosc})
    expectSameBytesAsOpenVdb(frame, options);
}

// The disk fills up 256 KiB into a frame of 10 MB (RLIMIT_FSIZE, which binds root too), encoded
// on one thread and on three: the error names the file and the system's reason, the frame
// written before is still whole under its name, and no temporary is left.
TEST_F(ioVdbWriter, AFullDiskLeavesTheFormerFileWhole) {
  const fs::path file = dir_ / "frame.vdb";
  const FrameData before = frameOf(1000, 5.0f), after = frameOf(200000, 40.0f);
  writeVdbPointCache(before, metadata(), file, kDefault);
  const std::string old = fileBytes(file);
  const tbb::global_control allowed(tbb::global_control::max_allowed_parallelism, 3);
  for (const int threads : {1, 3}) {
    SCOPED_TRACE(std::to_string(threads) + " threads");
    std::string message;
    {
      const test::FileSizeLimit limit(256 << 10);
      ASSERT_TRUE(limit.set());
      try {
        tbb::task_arena(threads).execute(
            [&] { writeVdbPointCache(after, metadata(), file, kDefault); });
      } catch (const std::runtime_error& e) {
        message = e.what();
      }
    }
    EXPECT_EQ(message, file.string() + ": error: cannot write (File too large)");
    EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 1);
    EXPECT_TRUE(fileBytes(file) == old);
  }
}

// The counting sort by leaf that writeVdbPointCache groups points with, against the sort of
// every point's (leaf, voxel, row) it replaced: the same leaves in the same order, the same
// points in each voxel in the same order, so the same bytes.
void expectGroupingsAgree(const FrameData& frame) {
  const tbb::global_control allowed(tbb::global_control::max_allowed_parallelism, kMostThreads);
  for (const VdbCacheOptions& options : {kDefault, kFixed16}) {
    SCOPED_TRACE(vdbPositionsName(options.positions));
    const std::string sorted = detail::vdbPointCacheBytes(
        frame, metadata(), options, VdbEncoder::Parallel, VdbGrouping::Sorted);
    for (const int threads : kThreads) {
      SCOPED_TRACE(std::to_string(threads) + " threads");
      tbb::task_arena arena(threads);
      std::string fastest;
      arena.execute([&] {
        fastest = detail::vdbPointCacheBytes(frame, metadata(), options, VdbEncoder::Parallel,
                                             VdbGrouping::Fastest);
      });
      EXPECT_EQ(fastest.size(), sorted.size());
      EXPECT_TRUE(fastest == sorted)
          << "the groupings differ first at byte " << firstDifference(fastest, sorted);
    }
    // The placement loops' clones for each instruction set this machine runs, on two threads
    // (the sort places points with scalar code alone).
    for (const Isa isa : {Isa::Baseline, Isa::Avx2, Isa::Avx512}) {
      if (!isaAvailable(isa)) continue;
      SCOPED_TRACE(isaName(isa));
      const ForcedIsa forced(isa);
      std::string fastest;
      tbb::task_arena(2).execute([&] {
        fastest = detail::vdbPointCacheBytes(frame, metadata(), options, VdbEncoder::Parallel,
                                             VdbGrouping::Fastest);
      });
      EXPECT_TRUE(fastest == sorted)
          << "the groupings differ first at byte " << firstDifference(fastest, sorted);
    }
  }
}

// Several chunks of rows (the counting sort's unit), custom attributes of every kind.
TEST(ioVdbGrouping, ManyChunksGroupAsTheSortDid) {
  expectGroupingsAgree(frameOf(300000, 30.0f, {"heat", "hitnum", "Cd_r", "Cd_g", "Cd_b"}));
}

// Points crowded into few voxels (rows interleaved between them), ties at half a voxel either
// side of 0, −0.0, NaN, infinities and coordinates at and beyond ±2³⁰ (all placed in voxel 0),
// the largest floats below 0.5 and 2³⁰: every way a point's voxel is chosen.
TEST(ioVdbGrouping, AwkwardCoordinatesGroupAsTheSortDid) {
  FrameData frame = frameOf(200000, 20.0f);
  const float special[] = {0.5f,
                           -0.5f,
                           1.5f,
                           -1.5f,
                           -0.0f,
                           0.0f,
                           std::nextafter(0.5f, 0.0f),
                           -std::nextafter(0.5f, 0.0f),
                           std::numeric_limits<float>::quiet_NaN(),
                           std::numeric_limits<float>::infinity(),
                           -std::numeric_limits<float>::infinity(),
                           1073741824.0f,
                           -1073741824.0f,
                           std::nextafter(1073741824.0f, 0.0f),
                           3.5f,
                           -7.5f,
                           8.0f,
                           -8.0f};
  constexpr std::size_t kSpecial = std::size(special);
  for (std::size_t k = 0; k < frame.size(); ++k) {
    const auto i = static_cast<Eigen::Index>(k);
    if (k % 3 == 0) {  // a third in the voxels around the origin
      for (int c = 0; c < 3; ++c)
        frame.position[c][i] = std::round(frame.position[c][i] / 8.0f) * 0.5f;
    } else if (k % 7 == 1) {
      for (int c = 0; c < 3; ++c) {
        frame.position[c][i] = special[(k / 7 + 5 * static_cast<std::size_t>(c)) % kSpecial];
      }
    }
  }
  expectGroupingsAgree(frame);
  // The same without the far finite ones: NaN, the infinities and ±2³⁰ sit in voxel 0, so the
  // leaves' box holds the points alone and the counting sort (placeRows) places them all.
  for (std::size_t k = 0; k < frame.size(); ++k) {
    for (int c = 0; c < 3; ++c) {
      float& x = frame.position[c][static_cast<Eigen::Index>(k)];
      if (std::abs(x) >= 1e6f && std::abs(x) < 1073741824.0f) x = 0.25f;
    }
  }
  expectGroupingsAgree(frame);
}

// Far from the origin (the box of leaves does not reach voxel 0), and spread so wide that the
// leaves' box is too large to count in (the sort is used then; the bytes are the same anyway).
TEST(ioVdbGrouping, FarAndWidelySpreadPointsGroupAsTheSortDid) {
  FrameData frame = frameOf(50000, 40.0f);
  for (Eigen::Index i = 0; i < static_cast<Eigen::Index>(frame.size()); ++i)
    for (int c = 0; c < 3; ++c) frame.position[c][i] += c == 1 ? -100000.0f : 250000.0f;
  expectGroupingsAgree(frame);
  // (A few hundred such leaves: each far leaf costs OpenVDB a tree's nodes of its own.)
  for (Eigen::Index i = 0; i < static_cast<Eigen::Index>(frame.size()); i += 200)
    for (int c = 0; c < 3; ++c) frame.position[c][i] = -frame.position[c][i] * 1000.0f;
  expectGroupingsAgree(frame);
  expectGroupingsAgree(frameOf(0, 1.0f));
  expectGroupingsAgree(test::onePointFrame());
}

// Columns whose rows all hold the same bits (as a frame's lives or masses often do) are not
// moved, their one value stored for every point: the same bytes, the same values read back, in
// either grouping. A column that differs in one row only is not one of them: −0.0 in the last
// row of 0.0, or a value past the blocks of rows checked first.
TEST_F(ioVdbWriter, UniformColumnsGiveOpenVdbsBytes) {
  const std::size_t n = 30000;
  FrameData frame = frameOf(n, 30.0f, {"hitnum", "Cd_r", "Cd_g", "Cd_b", "w", "heat"});
  const auto last = static_cast<Eigen::Index>(n - 1);
  frame.life.setConstant(std::numeric_limits<float>::infinity());
  frame.mass.setConstant(-0.0f);
  frame.age.setConstant(0.0f);
  frame.age[last] = -0.0f;
  frame.attributes[0].setConstant(7.0f);                               // hitnum: an int
  frame.attributes[2].setConstant(0.5f);                               // Cd's green lane
  frame.attributes[4].setConstant(std::bit_cast<float>(0x7fc01234u));  // a NaN's payload
  frame.attributes[5].setConstant(2.0f);
  frame.attributes[5][20000] = 2.5f;
  for (const VdbCacheOptions& options : {kDefault, kFixed16, kBlosc})
    expectSameBytesAsOpenVdb(frame, options);
  expectGroupingsAgree(frame);
}

}  // namespace
}  // namespace tickfx::io
