// Frame caches and frame schedules: what is written reads back bit for bit, and bad files fail
// loudly with their name and place.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <tbb/task_arena.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <memory>
#include <numeric>
#include <string>
#include <utility>
#include <vector>

#include "app/FrameTimes.h"
#include "fields/ForceSet.h"
#include "fields/Gravity.h"
#include "io/cache/AttributeGroups.h"
#include "io/cache/CsvCache.h"
#include "io/cache/FrameData.h"
#include "io/cache/PlyCache.h"
#include "io/util/AtomicFile.h"
#include "io/util/UninitialisedVector.h"
#include "particles/ParticleSystem.h"
#include "tests/support/FileBytes.h"

namespace fs = std::filesystem;

namespace tickfx::io {
namespace {

class Caches : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("tickfx_caches_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // 300 particles with spread, jittered lifetimes (some already dead), a custom attribute and
  // an α strictly between 0 and 1, so interpolation and every column are exercised.
  static FrameData sampleFrame() {
    SystemSettings settings;
    settings.stepRateHz = 50;
    EmitterSettings e;
    e.shape = SphereShape{0.3, false};
    e.bursts = {{0.0, 300}};
    e.speed = 4.0;
    e.spreadDegrees = 60.0;
    e.lifetime = 0.2;
    e.lifetimeJitter = 0.9;
    e.mass = 0.25;
    ForceSet forces;
    forces.add(std::make_unique<Gravity>());
    ParticleSystem system(settings, {e}, std::move(forces));
    const std::size_t heat = system.editPool().addAttribute("heat", 1.5f);
    system.advance(frameDuration({24, 1}) * 3);
    for (std::size_t i = 0; i < system.pool().size(); ++i) {
      system.editPool().attribute(heat)[static_cast<Eigen::Index>(i)] =
          0.1f * static_cast<float>(i);
    }
    EXPECT_GT(system.alpha(), 0.0f);
    return captureFrame(system, 3, 0.125);
  }

  static void expectSameBits(const FrameData& a, const FrameData& b) {
    ASSERT_EQ(a.size(), b.size());
    EXPECT_EQ(a.id, b.id);
    for (int c = 0; c < 3; ++c) {
      EXPECT_EQ(std::memcmp(a.position[c].data(), b.position[c].data(), a.size() * 4), 0);
      EXPECT_EQ(std::memcmp(a.velocity[c].data(), b.velocity[c].data(), a.size() * 4), 0);
    }
    EXPECT_EQ(std::memcmp(a.age.data(), b.age.data(), a.size() * 4), 0);
    EXPECT_EQ(std::memcmp(a.life.data(), b.life.data(), a.size() * 4), 0);
    EXPECT_EQ(std::memcmp(a.mass.data(), b.mass.data(), a.size() * 4), 0);
    ASSERT_EQ(a.attributeNames, b.attributeNames);
    EXPECT_EQ(std::memcmp(a.attributes[0].data(), b.attributes[0].data(), a.size() * 4), 0);
  }

  fs::path dir_;
};

TEST_F(Caches, CsvRoundTripIsBitExact) {
  const FrameData frame = sampleFrame();
  ASSERT_GT(frame.size(), 50u);
  ASSERT_LT(frame.size(), 300u) << "some particles should have died";
  writeCsvCache(frame, dir_ / "f.csv");
  expectSameBits(readCsvCache(dir_ / "f.csv"), frame);
  std::ifstream in(dir_ / "f.csv");
  std::string header;
  std::getline(in, header);
  EXPECT_EQ(header, "id,px,py,pz,vx,vy,vz,age,life,mass,heat");
}

// Regression (issue 10, item 12): a CSV cache with CRLF line ends (one that went through a
// Windows tool) failed with "bad number '0.002...\r'". It reads back the same bits.
TEST_F(Caches, CsvWithCrlfLineEndsReadsBackTheSameBits) {
  const FrameData frame = sampleFrame();
  writeCsvCache(frame, dir_ / "f.csv");
  std::string text = test::fileBytes(dir_ / "f.csv");
  std::string crlf;
  for (char ch : text) crlf += ch == '\n' ? std::string("\r\n") : std::string(1, ch);
  std::ofstream(dir_ / "crlf.csv", std::ios::binary) << crlf;
  expectSameBits(readCsvCache(dir_ / "crlf.csv"), frame);
}

TEST_F(Caches, PlyRoundTripIsBitExactWithHeaderAndMetadata) {
  const FrameData frame = sampleFrame();
  writePlyCache(frame, dir_ / "f.ply");
  const FrameData back = readPlyCache(dir_ / "f.ply");
  expectSameBits(back, frame);
  EXPECT_EQ(back.frame, 3);
  EXPECT_EQ(back.timeSeconds, 0.125);
  // Header, then exactly 8 + 10·4 bytes per particle (double id, ten floats).
  const std::string expectedHeader =
      "ply\nformat binary_little_endian 1.0\ncomment tickfx frame 3\ncomment time 0.125\n"
      "element vertex " +
      std::to_string(frame.size()) +
      "\nproperty double id\nproperty float x\nproperty float y\nproperty float z\n"
      "property float vx\nproperty float vy\nproperty float vz\nproperty float age\n"
      "property float life\nproperty float mass\nproperty float heat\nend_header\n";
  EXPECT_EQ(fs::file_size(dir_ / "f.ply"), expectedHeader.size() + frame.size() * 48);
  std::ifstream in(dir_ / "f.ply", std::ios::binary);
  std::string head(expectedHeader.size(), '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  EXPECT_EQ(head, expectedHeader);
}

// The body of a PLY cache of `frame`, made value by value: each row's id as a double, then the
// values of `columns` (the header's order: the standard columns, then the frame's attributes),
// ints for Houdini's integer attributes.
std::string expectedPlyBody(const FrameData& frame, const std::vector<FloatColumn*>& columns) {
  const std::size_t standard = columns.size() - frame.attributes.size();
  std::string body;
  const auto put = [&](const void* value, std::size_t bytes) {
    body.append(static_cast<const char*>(value), bytes);
  };
  for (std::size_t i = 0; i < frame.size(); ++i) {
    const auto e = static_cast<Eigen::Index>(i);
    const double id = static_cast<double>(frame.id[i]);
    put(&id, sizeof id);
    for (std::size_t c = 0; c < columns.size(); ++c) {
      if (c >= standard && isIntAttribute(frame.attributeNames[c - standard])) {
        const auto v = static_cast<std::int32_t>((*columns[c])[e]);
        put(&v, sizeof v);
      } else {
        put(&(*columns[c])[e], sizeof(float));
      }
    }
  }
  return body;
}

// The rows are stored a block at a time (32768 rows), the standard columns a row at a time in
// 16-byte stores that reach into the next row, the other float columns four, two or one at a
// time: every byte of the body, over three blocks, the last one partial, with no other columns,
// with two, and with runs of floats of every length between int columns, on 1 and 2 threads.
// Values with every bit pattern that matters: NaNs with payloads, −0.0, subnormals, infinities.
TEST_F(Caches, PlyBodiesAreTheRowsValueByValueAcrossBlocks) {
  const float special[] = {std::bit_cast<float>(0x7fc01234u),
                           std::bit_cast<float>(0xff812345u),
                           -0.0f,
                           1e-40f,
                           -std::numeric_limits<float>::infinity(),
                           3.5f};
  for (const std::vector<std::string>& names :
       {std::vector<std::string>{}, std::vector<std::string>{"heat", "hitnum"},
        // Runs of floats of 7 (4 + 2 + 1), an int, 1 and 2 (PlyCache's stores a run at once).
        std::vector<std::string>{"Cd_r", "Cd_g", "Cd_b", "Alpha", "pscale", "heat", "rest",
                                 "hitnum", "u", "contacts", "w", "t"}}) {
    FrameData frame;
    frame.frame = 7;
    frame.resize(70001, names);
    std::vector<FloatColumn*> columns = {&frame.position.x, &frame.position.y, &frame.position.z,
                                         &frame.velocity.x, &frame.velocity.y, &frame.velocity.z,
                                         &frame.age,        &frame.life,       &frame.mass};
    for (FloatColumn& a : frame.attributes) columns.push_back(&a);
    for (std::size_t i = 0; i < frame.size(); ++i) {
      frame.id[i] = 3 * i + (std::uint64_t{1} << 40);
      for (std::size_t c = 0; c < columns.size(); ++c) {
        const std::size_t k = (i + 7 * c) % 101;
        const bool whole = c >= 9 && isIntAttribute(names[c - 9]);  // (hitnum: no NaN to cast)
        (*columns[c])[static_cast<Eigen::Index>(i)] =
            k < std::size(special) && !whole
                ? special[k]
                : static_cast<float>(c) + (whole ? 1.0f : 0.25f) * static_cast<float>(i);
      }
    }
    const std::string expected = expectedPlyBody(frame, columns);
    for (const int threads : {1, 2}) {
      SCOPED_TRACE(std::to_string(names.size()) + " other columns, " + std::to_string(threads) +
                   " threads");
      tbb::task_arena(threads).execute([&] { writePlyCache(frame, dir_ / "f.ply"); });
      const std::string file = test::fileBytes(dir_ / "f.ply");
      const std::size_t header = file.find("end_header\n");
      ASSERT_NE(header, std::string::npos);
      const std::string body = file.substr(header + std::strlen("end_header\n"));
      ASSERT_EQ(body.size(), expected.size());
      EXPECT_TRUE(body == expected)
          << "first difference at body byte "
          << std::mismatch(body.begin(), body.end(), expected.begin()).first - body.begin();
    }
  }
}

TEST_F(Caches, TruncatedOrForeignFilesAreRefusedByName) {
  const FrameData frame = sampleFrame();
  writePlyCache(frame, dir_ / "f.ply");
  fs::resize_file(dir_ / "f.ply", fs::file_size(dir_ / "f.ply") - 7);
  // Rows of an 8-byte id and 10 floats (9 columns and "heat"); the count is checked against the
  // file's size before any row is allocated.
  const std::size_t rows = frame.size();
  try {
    readPlyCache(dir_ / "f.ply");
    FAIL() << "a truncated PLY was read";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), (dir_ / "f.ply").string() + ": truncated body (" +
                                         std::to_string(rows) + " vertices of 48 bytes, " +
                                         std::to_string(rows * 48 - 7) +
                                         " bytes after the header)");
  }
  std::ofstream(dir_ / "bad.csv")
      << "id,px,py,pz,vx,vy,vz,age,life,mass\n0,1,2,3,4,5,6,7,8,9\n1,1,2,x,4,5,6,7,8,9\n";
  try {
    readCsvCache(dir_ / "bad.csv");
    FAIL() << "a malformed CSV was read";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), (dir_ / "bad.csv").string() + ":3: bad number 'x'");
  }
}

// Found by fuzz_ply: an id that is not a whole number in [0, 2⁶⁴) was converted to uint64_t
// (undefined behaviour); a vertex count far past the file's end was allocated before the body was
// read.
TEST_F(Caches, PlyIdsThatAreNoIdAndCountsPastTheFileAreRefused) {
  const FrameData frame = sampleFrame();
  writePlyCache(frame, dir_ / "f.ply");
  const std::string good = test::fileBytes(dir_ / "f.ply");
  const std::size_t body = good.find("end_header\n") + 11;
  const fs::path bad = dir_ / "bad.ply";
  auto refusal = [&](const std::string& bytes) -> std::string {
    std::ofstream(bad, std::ios::binary) << bytes;
    try {
      readPlyCache(bad);
      return "accepted";
    } catch (const std::runtime_error& e) {
      return e.what();
    }
  };
  const std::pair<double, const char*> notIds[] = {
      {-1.0, "-1"}, {0.5, "0.5"}, {0x1p64, "1.8446744073709552e+19"}, {std::nan(""), "nan"}};
  for (const auto& [id, text] : notIds) {
    std::string bytes = good;
    std::memcpy(bytes.data() + body + 48, &id, sizeof id);  // the second vertex
    EXPECT_EQ(refusal(bytes),
              bad.string() + ": vertex 1: id " + text + " is not a whole number in [0, 2^64)");
  }
  std::string huge = good;
  const std::string count = "element vertex " + std::to_string(frame.size());
  huge.replace(huge.find(count), count.size(), "element vertex 1000000000000");
  EXPECT_EQ(refusal(huge), bad.string() + ": truncated body (1000000000000 vertices of 48 bytes, " +
                               std::to_string(frame.size() * 48) + " bytes after the header)");
}

TEST_F(Caches, AFailedWriteLeavesTheOldFileAndNoTemporary) {
  const FrameData frame = sampleFrame();
  writeCsvCache(frame, dir_ / "f.csv");
  const auto before = fs::file_size(dir_ / "f.csv");
  fs::create_directories(dir_ / "blocked.csv");  // a folder where the file should go
  EXPECT_THROW(writeCsvCache(frame, dir_ / "blocked.csv"), std::exception);
  EXPECT_EQ(fs::file_size(dir_ / "f.csv"), before);
  for (const auto& entry : fs::directory_iterator(dir_)) {
    EXPECT_EQ(entry.path().string().find(".tmp"), std::string::npos) << entry.path();
  }
}

// writeFileAtomically's stream takes blocks as large as its buffer (64 KiB) past the buffer, at
// offsets on 64 KiB boundaries: a block's first bytes top the buffer up, its last ones stay in it.
// Whatever the sizes, the flushes between them and the offsets they leave, the file holds every
// byte in the order written.
TEST_F(Caches, WritesOfAnySizeReachTheFileInTheirOrder) {
  std::string expected;
  std::uint32_t state = 12345;
  const auto bytes = [&](std::size_t n) {
    std::string b(n, '\0');
    for (char& c : b) c = static_cast<char>((state = state * 1664525u + 1013904223u) >> 24);
    return b;
  };
  const fs::path path = dir_ / "pieces.bin";
  writeFileAtomically(path, [&](std::ostream& out) {
    // (size, flush after): a header, blocks of a PLY body, a block exactly the buffer's size,
    // one of a multiple of it, and blocks after flushes that leave the file off a boundary.
    const std::pair<std::size_t, bool> pieces[] = {
        {300, false},    {1441792, false}, {1441792, false}, {70000, false}, {5, false},
        {65536, false},  {17, true},       {65536, false},   {196625, true}, {65535, false},
        {131072, false}, {100, true},      {200000, false},  {1, false},     {65537, false}};
    for (const auto& [size, flush] : pieces) {
      const std::string piece = bytes(size);
      out.write(piece.data(), static_cast<std::streamsize>(piece.size()));
      if (flush) out.flush();
      expected += piece;
    }
  });
  const std::string written = test::fileBytes(path);
  ASSERT_EQ(written.size(), expected.size());
  EXPECT_TRUE(written == expected);
}

// The size foreseen for a file (its blocks allocated at once) changes nothing of what is
// written: a file of fewer bytes is that size, the blocks foreseen past it given back; one of
// more bytes holds them all.
TEST_F(Caches, AFileOfOtherThanTheSizeForeseenHoldsWhatWasWritten) {
  const std::string body(300000, 'x');
  for (const std::size_t foreseen : {std::size_t{1}, body.size(), std::size_t{8} << 20}) {
    SCOPED_TRACE(std::to_string(foreseen) + " bytes foreseen");
    const fs::path path = dir_ / ("foreseen" + std::to_string(foreseen) + ".bin");
    writeFileAtomically(
        path,
        [&](std::ostream& out) {
          out.write(body.data(), static_cast<std::streamsize>(body.size()));
        },
        Durability::Renamed, foreseen);
    const std::string written = test::fileBytes(path);
    EXPECT_TRUE(written == body) << written.size() << " bytes";
    struct stat st {};
    ASSERT_EQ(::stat(path.c_str(), &st), 0);
    EXPECT_LT(static_cast<std::size_t>(st.st_blocks) * 512, std::size_t{2} << 20);
  }
}

// The bytes of this process's pages in memory (Linux: /proc/self/statm).
std::size_t residentBytes() {
  std::ifstream statm("/proc/self/statm");
  std::size_t pages = 0, resident = 0;
  statm >> pages >> resident;
  return resident * static_cast<std::size_t>(::sysconf(_SC_PAGESIZE));
}

// A frame's ids are an UninitialisedVector: resize() writes nothing (no serial zero-fill before
// the parallel copy that writes every id), so 64 MiB of new ids make no page resident where a
// std::vector's would make all of them; large ones start on a 2 MiB page like the pool's columns;
// the rest is a std::vector's.
TEST(UninitialisedVector, ResizeWritesNothingAndLargeStorageStartsOnAHugePage) {
  if (!fs::exists("/proc/self/statm")) GTEST_SKIP() << "no /proc/self/statm";
  constexpr std::size_t kIds = std::size_t{8} << 20;  // 64 MiB
  UninitialisedVector<std::uint64_t> ids;
  const std::size_t before = residentBytes();
  ids.resize(kIds);
  const std::size_t after = residentBytes();
  EXPECT_LT(after > before ? after - before : 0, kIds * sizeof(std::uint64_t) / 2);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(ids.data()) % (std::uintptr_t{2} << 20), 0u);
  std::iota(ids.begin(), ids.end(), std::uint64_t{7});
  EXPECT_EQ(ids[kIds - 1], kIds + 6);
  ids.push_back(5);  // a std::vector's growth, values kept
  EXPECT_EQ(ids.back(), 5u);
  EXPECT_EQ(ids[kIds - 1], kIds + 6);
  ids.assign(3, 9);
  EXPECT_EQ(ids, (UninitialisedVector<std::uint64_t>{9, 9, 9}));
  UninitialisedVector<std::uint64_t> small{1, 2};
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(small.data()) % 64, 0u);
}

TEST(FrameTimes, SchedulesEndExactlyWhereAsked) {
  const Flicks fiveSeconds = 5 * kFlicksPerSecond;
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    const std::vector<Flicks> frames = app::jitteredFrames(seed, fiveSeconds);
    EXPECT_EQ(std::accumulate(frames.begin(), frames.end(), Flicks{0}), fiveSeconds);
    for (std::size_t i = 0; i + 1 < frames.size(); ++i) {
      EXPECT_GE(frames[i], kFlicksPerSecond / 240);
      EXPECT_LE(frames[i], kFlicksPerSecond / 10);
    }
    EXPECT_EQ(frames, app::jitteredFrames(seed, fiveSeconds)) << "a pure function of the seed";
  }
  EXPECT_NE(app::jitteredFrames(1, fiveSeconds), app::jitteredFrames(2, fiveSeconds));
  const std::vector<Flicks> ntsc =
      app::fixedRateFrames(app::parseFrameRate("30000/1001"), fiveSeconds);
  EXPECT_EQ(ntsc.size(), 150u);  // 149 whole frames of 1001/30000 s and a shorter last one
  EXPECT_EQ(ntsc.front(), 23'543'520);
  EXPECT_EQ(std::accumulate(ntsc.begin(), ntsc.end(), Flicks{0}), fiveSeconds);
  EXPECT_THROW(app::parseFrameRate("0"), std::invalid_argument);
  EXPECT_THROW(app::parseFrameRate("24/"), std::invalid_argument);
  // 705600000 = 2⁹·3²·5⁵·7²: 1/11 s is not a whole number of flicks.
  EXPECT_THROW(app::parseFrameRate("11"), std::invalid_argument);
}

}  // namespace
}  // namespace tickfx::io
