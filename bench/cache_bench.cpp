// Caches at disk speed (issue 16): how fast the per-frame cache writers are against the fastest
// write of the same bytes, and how much of the writing a run hides behind the simulation.
//
//   cache_bench                   sizes 10⁴, 10⁶ and 10⁷, overlap at 10⁶ (about 3 minutes on 2
//                                 cores; a 10⁷ CSV file is 0.85 GB)
//   cache_bench --quick           smoke run: sizes 10⁴ and 10⁵, overlap at 10⁵, short timings
//   cache_bench --sizes=1e4,1e6   only these particle counts for the writers
//   cache_bench --overlap=1e6     particles of the overlap part (0: skip it)
//   cache_bench --rounds=3        times each overlap case is run (the median is reported)
//   cache_bench --dir=PATH        write in a fresh folder inside PATH (default: inside /tmp)
//   cache_bench --min-time=0.5 --reps=9
//
// 1. Writers against dd. One synthetic frame of N particles with the default attributes (id,
//    position, velocity, age, life, mass; no custom attribute), uniform in a 100 m box so that a
//    VDB grid has many leaves. Each format (csv, ply, vdb as by default, vdb with blosc, vdb with
//    16-bit positions) is timed against a "dd": the same number of bytes written with write() in
//    1 MiB blocks into a temporary, closed and renamed into place, as writeFileAtomically does,
//    so k = writer / dd is what the format costs beyond moving its bytes into the kernel. The
//    writers run with TBB's default thread count; at 10⁶ also on 1 thread (a task_arena), and
//    PLY with Durability::Synced (`tickfx run --durable`) against a dd that fsyncs alike.
// 2. Overlap. A real effect (a burst of N particles in a 100 m box under gravity, 120 Hz ticks,
//    24 fps) built with parseEffect and buildOfflineSystem, one frame advanced as warm-up, then
//    12 frames: (a) simulated and captured only; (b) the captured frames written only, with
//    writeFrameCaches; (c) simulated with a BackgroundWriter writing on its thread, as `tickfx
//    run` does; (d) the same not overlapped (`--no-overlap`). Every case starts from a system
//    built and warmed up anew, and the bench checks that all start, and end, in the same state.
//
// The page cache: a write returns once its bytes are in the kernel's page cache, and these
// files are deleted seconds later, before the kernel writes them back (it starts after 30 s, or
// when dirty pages pass a tenth of the free memory). So the figures, dd's as well, are the speed of
// writing to the page cache, not to the disk, unless the machine's memory is smaller than the
// data. A run that writes more frames than the page cache holds goes at the disk's speed
// whatever the writer; the bench prints the memory so the reader can tell which case holds.
// In a VM whose balloon reports free pages to the host (virtio-balloon free page reporting),
// memory left free for a couple of seconds goes back to the host and the next write into it
// faults it in again, so a write is slower the longer the memory it fills stayed free. Files of
// 10⁷ particles take seconds, so their rows, dd's too, vary the most.
//
// Timing: the cases of one format take turns batch by batch, a tick being one file, and a case's
// figure is the median over its batches of the time per file (BenchHarness.h). Each file has a
// name of its own and the files are deleted between batches (each case's `after`), outside the
// timed part: deleting a file can cost as much as dd's whole write of it, more once its pages are
// written back, so timing it would pull every ratio towards 1.
//
// Output: the tables, then one line a figure, `name: value unit (ratios, targets)`.
#include <fcntl.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <tbb/info.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <chrono>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <functional>
#include <iterator>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include "BenchHarness.h"
#include "io/cache/BackgroundWriter.h"
#include "io/cache/CsvCache.h"
#include "io/cache/FrameCaches.h"
#include "io/cache/FrameData.h"
#include "io/cache/PlyCache.h"
#include "io/cache/VdbCacheOptions.h"
#include "io/cache/VdbPointCache.h"
#include "io/effect/EffectBuilder.h"
#include "io/effect/EffectParser.h"
#include "io/util/AtomicFile.h"
#include "particles/Clock.h"
#include "particles/ParticleSystem.h"
#include "particles/Random.h"
#include "particles/StateHash.h"

namespace {

namespace bench = tickfx::bench;
using bench::threadsLabel;
namespace fs = std::filesystem;
namespace io = tickfx::io;

// ---- the synthetic frame ----------------------------------------------------------------------

constexpr std::uint64_t kSeed = 0x16cac4e5;
constexpr float kBoxHalf = 50.0f;  // m: a 100 m box, 1 m voxels, so up to 14³ VDB leaves
constexpr float kSpeed = 3.0f;     // m/s, each component

// Uniform in [-1, 1), from the top 24 bits so that every value is an exact float.
float symmetricUnit(std::uint64_t key) {
  return static_cast<float>(tickfx::splitmix64(kSeed ^ key) >> 40) * 0x1p-23f - 1.0f;
}

struct Row {
  float position[3], velocity[3], age;
};

// A pure function of the index, so that the file sizes can be estimated from a sample before
// any frame is built.
Row syntheticRow(std::size_t i) {
  const std::uint64_t k = 8 * static_cast<std::uint64_t>(i);
  Row r{};
  for (int c = 0; c < 3; ++c) {
    r.position[c] = kBoxHalf * symmetricUnit(k + static_cast<std::uint64_t>(c));
    r.velocity[c] = kSpeed * symmetricUnit(k + 3 + static_cast<std::uint64_t>(c));
  }
  r.age = 1.0f + symmetricUnit(k + 6);  // 0 to 2 s
  return r;
}

io::FrameData syntheticFrame(std::size_t n) {
  io::FrameData frame;
  frame.frame = 1;
  frame.timeSeconds = 1.0 / 24.0;
  frame.resize(n, {});
  for (std::size_t i = 0; i < n; ++i) {
    const Row r = syntheticRow(i);
    const auto e = static_cast<Eigen::Index>(i);
    frame.id[i] = i + 1;
    for (int c = 0; c < 3; ++c) {
      frame.position[c][e] = r.position[c];
      frame.velocity[c][e] = r.velocity[c];
    }
    frame.age[e] = r.age;
  }
  frame.life.setConstant(5.0f);
  frame.mass.setConstant(1.0f);
  return frame;
}

// ---- formats ----------------------------------------------------------------------------------

enum class Format { Csv, Ply, Vdb, VdbBlosc, VdbFixed16 };

struct FormatInfo {
  Format format;
  const char* name;
  const char* extension;
  double target;  // k = writer / dd asked for at 10⁶ particles on 2 threads
};

const FormatInfo kFormats[] = {
    {Format::Csv, "csv", "csv", 3.0},
    {Format::Ply, "ply", "ply", 1.2},
    {Format::Vdb, "vdb", "vdb", 3.0},
    {Format::VdbBlosc, "vdb blosc", "vdb", 3.0},
    {Format::VdbFixed16, "vdb fixed16", "vdb", 3.0},
};

// The size at which the targets are judged.
constexpr std::size_t kTargetSize = 1'000'000;

const io::VdbCacheMetadata kVdbMeta{"00000000cac4e516", 16, 120, "semi_implicit_euler", "bench"};

void writeFormat(Format format, const io::FrameData& frame, const fs::path& path,
                 io::Durability durability) {
  io::VdbCacheOptions options;
  switch (format) {
    case Format::Csv:
      io::writeCsvCache(frame, path, durability);
      return;
    case Format::Ply:
      io::writePlyCache(frame, path, durability);
      return;
    case Format::Vdb:
      break;
    case Format::VdbBlosc:
      options.compression = io::VdbCacheOptions::Compression::Blosc;
      break;
    case Format::VdbFixed16:
      options.positions = io::VdbCacheOptions::Positions::Fixed16;
      break;
  }
  io::writeVdbPointCache(frame, kVdbMeta, path, options, durability);
}

// Bytes of a CSV cache of `rows` synthetic rows, from a sample formatted the writer's way: the
// largest file of a run is a CSV one, and the disk check must come before it exists.
double estimateCsvBytes(std::size_t rows) {
  const std::size_t step = std::max<std::size_t>(1, rows / 20000);
  double bytes = 0.0;
  std::size_t sampled = 0;
  char text[32];
  const auto length = [&](auto value) {
    return static_cast<double>(std::to_chars(text, text + sizeof text, value).ptr - text);
  };
  for (std::size_t i = 0; i < rows; i += step, ++sampled) {
    const Row r = syntheticRow(i);
    double row = length(i + 1) + 1.0;  // the newline
    for (int c = 0; c < 3; ++c) row += 2.0 + length(r.position[c]) + length(r.velocity[c]);
    row += 3.0 + length(r.age) + length(5.0f) + length(1.0f);
    bytes += row;
  }
  return 64.0 + bytes / static_cast<double>(sampled) * static_cast<double>(rows);
}

double estimateLargestFile(std::size_t rows) {
  // 44 bytes a point for P, v, id, age, life, mass; each of the at most 14³ leaves adds its
  // voxel offsets and attribute headers, a few KiB.
  const double vdb = 44.0 * static_cast<double>(rows) + 8.0 * 1024 * 1024;
  return std::max(estimateCsvBytes(rows), vdb);
}

// ---- the dd side ------------------------------------------------------------------------------

[[noreturn]] void fail(const fs::path& path, const char* what) {
  throw io::WriteError(path, std::string(what) + ": " + std::strerror(errno));
}

// What `dd bs=1M` does, then what writeFileAtomically adds: a temporary renamed into place, and
// with Synced an fsync of the file before the rename and of the folder after.
void ddWrite(const fs::path& path, std::size_t bytes, io::Durability durability,
             const std::vector<char>& block) {
  fs::path temp = path;
  temp += ".tmp";
  const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd < 0) fail(temp, "open");
  for (std::size_t done = 0; done < bytes;) {
    const std::size_t want = std::min(block.size(), bytes - done);
    const ssize_t n = ::write(fd, block.data(), want);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) fail(temp, "write");
    done += static_cast<std::size_t>(n);
  }
  if (durability == io::Durability::Synced && ::fsync(fd) != 0) fail(temp, "fsync");
  if (::close(fd) != 0) fail(temp, "close");
  if (::rename(temp.c_str(), path.c_str()) != 0) fail(path, "rename");
  if (durability == io::Durability::Synced) {
    const int dir = ::open(path.parent_path().c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dir < 0) fail(path.parent_path(), "open");
    const bool synced = ::fsync(dir) == 0;
    ::close(dir);
    if (!synced) fail(path.parent_path(), "fsync");
  }
}

// ---- part 1: writers against dd ---------------------------------------------------------------

struct ResultRow {
  std::string format;
  double target;
  std::size_t n;
  int threads;
  bool synced;
  double bytes;
  double writer;  // seconds a file
  double dd;      // seconds a file of the same size, in the same run
  double stolen;  // the share of the machine's CPU time stolen while the writer ran
};

struct Part1 {
  std::vector<ResultRow> rows;
  bool sizesAgree = true;
};

// One format at one size: the writer with all threads, and at the reference size also on 1
// thread (and PLY synced), each against its dd, all taking turns.
void runFormat(const FormatInfo& f, const io::FrameData& frame, bool reference, const fs::path& dir,
               const bench::Timing& timing, int allThreads, Part1& out) {
  const std::size_t n = frame.size();
  std::size_t bytes = 0;  // the writer's file, learnt from its first one (every one is the same)
  std::uint64_t serial = 0;
  const auto nextPath = [&](const char* prefix, const char* extension) {
    return dir / (std::string(prefix) + "-" + std::to_string(serial++) + "." + extension);
  };
  const std::vector<char> block(1 << 20, 'x');
  tbb::task_arena oneThread(1);

  struct Writer {
    int threads;
    io::Durability durability;
    std::size_t index = 0;  // in `cases`
  };
  std::vector<Writer> writers{{allThreads, io::Durability::Renamed}};
  if (reference && allThreads > 1) writers.push_back({1, io::Durability::Renamed});
  const bool synced = reference && f.format == Format::Ply;
  if (synced) writers.push_back({allThreads, io::Durability::Synced});

  std::vector<bench::Case> cases;
  for (Writer& w : writers) {
    w.index = cases.size();
    std::string name = std::string(f.name) + ", " + threadsLabel(w.threads);
    if (w.durability == io::Durability::Synced) name += ", synced";
    cases.emplace_back(name, [&, w](std::int64_t files) {
      for (std::int64_t i = 0; i < files; ++i) {
        const fs::path path = nextPath("writer", f.extension);
        if (w.threads == allThreads) {
          writeFormat(f.format, frame, path, w.durability);
        } else {
          oneThread.execute([&] { writeFormat(f.format, frame, path, w.durability); });
        }
        if (bytes == 0) bytes = static_cast<std::size_t>(fs::file_size(path));
      }
    });
  }
  // After the writers: the first writer's calibration has given the size by then.
  const std::size_t ddIndex = cases.size();
  for (const io::Durability d : {io::Durability::Renamed, io::Durability::Synced}) {
    if (d == io::Durability::Synced && !synced) continue;
    cases.emplace_back(d == io::Durability::Synced ? "dd, synced" : "dd",
                       [&, d](std::int64_t files) {
                         for (std::int64_t i = 0; i < files; ++i)
                           ddWrite(nextPath("dd", "bin"), bytes, d, block);
                       });
  }

  // Every file of the group must have the writer's size: thread counts and durability change no
  // byte of a cache (the writers promise it), and dd writes exactly that many.
  const auto clean = [&] {
    for (const fs::directory_entry& e : fs::directory_iterator(dir)) {
      if (!e.is_regular_file() || e.file_size() != bytes) out.sizesAgree = false;
      fs::remove(e.path());
    }
  };
  for (bench::Case& c : cases) {
    c.after = [&clean] {
      clean();
      return true;
    };
  }
  bench::timeCases(cases, timing);

  for (const bench::Case& c : cases) {
    std::printf(
        "  %-28s %10.4f ms/file  (median of %zu batches of %lld; %.4f to %.4f; %.2f cores; %.1f %% "
        "stolen)\n",
        c.name.c_str(), 1e3 * c.seconds(), c.secondsPerTick.size(), static_cast<long long>(c.batch),
        1e3 * c.fastest(), 1e3 * c.slowest(), c.cores(), 100.0 * c.stolenShare());
  }
  std::fflush(stdout);
  for (const Writer& w : writers) {
    const bool sync = w.durability == io::Durability::Synced;
    const bench::Case& dd = cases[ddIndex + (sync ? 1 : 0)];
    const bench::Case& writer = cases[w.index];
    out.rows.push_back({f.name, f.target, n, w.threads, sync, static_cast<double>(bytes),
                        writer.seconds(), dd.seconds(), writer.stolenShare()});
  }
}

void printPart1(const Part1& p, int allThreads) {
  std::printf(
      "\nwriters against dd (the same bytes with write() in 1 MiB blocks, renamed alike); "
      "MB = 10^6 bytes\n");
  // Beside the verdict, the share of the machine's CPU time the hypervisor took while the writer
  // ran: a busy host slows a writer's threads more than dd's one, and a row with more than a few
  // percent stolen measures the host.
  std::printf("%-12s %-10s %9s %10s %12s %12s %9s %12s %7s %7s %-5s %7s\n", "format", "threads",
              "N", "file MB", "writer s", "particles/s", "MB/s", "dd s", "k", "target", "met",
              "stolen");
  for (const ResultRow& r : p.rows) {
    const double k = r.writer / r.dd;
    // The targets are set at 10⁶ on all threads with the default durability; other rows show
    // the comparison in brackets.
    const bool judged = r.n == kTargetSize && r.threads == allThreads && !r.synced;
    const bool met = k <= r.target;
    const std::string verdict = judged ? (met ? "yes" : "NO") : (met ? "(yes)" : "(no)");
    std::string threads = std::to_string(r.threads);
    if (r.synced) threads += " synced";
    char target[16];
    std::snprintf(target, sizeof target, "<=%.1f", r.target);
    char stolen[16];
    std::snprintf(stolen, sizeof stolen, "%.1f%%", 100.0 * r.stolen);
    std::printf("%-12s %-10s %9.0e %10.3f %12.4g %12.4g %9.0f %12.4g %7.2f %7s %-5s %7s\n",
                r.format.c_str(), threads.c_str(), static_cast<double>(r.n), r.bytes / 1e6,
                r.writer, static_cast<double>(r.n) / r.writer, r.bytes / 1e6 / r.writer, r.dd, k,
                target, verdict.c_str(), stolen);
  }

  const auto find = [&](const std::string& format, int threads, bool synced) -> const ResultRow* {
    for (const ResultRow& r : p.rows) {
      if (r.n == kTargetSize && r.format == format && r.threads == threads && r.synced == synced)
        return &r;
    }
    return nullptr;
  };
  if (allThreads > 1 && find("ply", 1, false) != nullptr) {
    std::printf("\nparallel gain at 10^6, writer s on 1 thread / on %d:", allThreads);
    for (const FormatInfo& f : kFormats) {
      const ResultRow* one = find(f.name, 1, false);
      const ResultRow* all = find(f.name, allThreads, false);
      if (one != nullptr && all != nullptr)
        std::printf("  %s %.2f", f.name, one->writer / all->writer);
    }
    std::printf("\n");
  }
  const ResultRow* renamed = find("ply", allThreads, false);
  const ResultRow* durable = find("ply", allThreads, true);
  if (renamed != nullptr && durable != nullptr) {
    std::printf(
        "--durable at 10^6, PLY: %.4f s a frame against %.4f s (+%.4f s, x%.2f); dd with fsync "
        "%.4f s against %.4f s\n",
        durable->writer, renamed->writer, durable->writer - renamed->writer,
        durable->writer / renamed->writer, durable->dd, renamed->dd);
  }
  if (!p.sizesAgree)
    std::printf("CHECK FAILED: a file of a group had another size than the writer's first\n");
}

// ---- part 2: overlap --------------------------------------------------------------------------

constexpr int kTimedFrames = 12;

std::string effectText(std::size_t n) {
  char text[1024];
  std::snprintf(text, sizeof text,
                "format_version = 1\n"
                "[simulation]\n"
                "step_rate = 120\n"
                "seed = 16\n"
                "max_particles = %zu\n"
                "[[emitters]]\n"
                "name = \"burst\"\n"
                "shape = \"box\"\n"
                "position = [0.0, 50.0, 0.0]\n"
                "size = [100.0, 100.0, 100.0]\n"
                "bursts = [{ time = 0.0, count = %zu }]\n"
                "direction = [0.0, 1.0, 0.0]\n"
                "speed = 4.0\n"
                "speed_jitter = 0.5\n"
                "spread = 180.0\n"
                "lifetime = 5.0\n"
                "lifetime_jitter = 0.2\n"
                "[[forces]]\n"
                "type = \"gravity\"\n"
                "[output]\n"
                "fps = 24\n",
                n, n);
  return text;
}

// Wall and process CPU seconds (all threads) of each round of one case.
struct Rounds {
  std::vector<double> wall, cpu;
};

struct OverlapRow {
  std::string format;
  std::size_t n = 0;
  Rounds simulate, write, overlapped, inlined;
  double writeSecondsOverlapped = 0.0, writeSecondsInline = 0.0;  // the writer's own clock
};

using Seconds = std::chrono::duration<double>;

// A system built anew, with the warm-up frame (the burst) advanced: every case starts here.
std::unique_ptr<tickfx::ParticleSystem> warmSystem(const io::EffectSettings& effect,
                                                   tickfx::Flicks frame) {
  std::unique_ptr<tickfx::ParticleSystem> system = io::buildOfflineSystem(effect, std::nullopt);
  system->advance(frame);
  return system;
}

// One overlap row; returns false when a case did not start or end in the same state as the
// others.
bool runOverlap(io::CacheFormat format, const io::EffectSettings& effect, std::size_t n, int rounds,
                const fs::path& dir, std::vector<OverlapRow>& rows) {
  const tickfx::Flicks frame = tickfx::frameDuration(tickfx::FrameRate{24, 1});
  io::CacheTargets targets;
  targets.directory = dir / "overlap";
  targets.formats = {format};
  OverlapRow row;
  row.format = io::cacheFormatName(format);
  row.n = n;

  std::optional<std::uint64_t> startHash, endHash;
  bool same = true;
  const auto start = [&] {
    std::unique_ptr<tickfx::ParticleSystem> system = warmSystem(effect, frame);
    const std::uint64_t h = tickfx::stateHash(system->pool());
    if (!startHash) startHash = h;
    same = same && h == *startHash;
    return system;
  };
  const auto end = [&](const tickfx::ParticleSystem& system) {
    const std::uint64_t h = tickfx::stateHash(system.pool());
    if (!endHash) endHash = h;
    same = same && h == *endHash;
  };
  const auto simulate = [&](tickfx::ParticleSystem& system, auto&& take) {
    tickfx::Flicks elapsed = frame;
    for (int f = 2; f < 2 + kTimedFrames; ++f) {
      system.advance(frame);
      elapsed += frame;
      take(io::captureFrame(system, f, tickfx::secondsFromFlicks(elapsed)));
    }
  };
  // Untimed: each writing case starts in an empty folder and its files go afterwards.
  const auto freshFolder = [&] {
    fs::remove_all(targets.directory);
    fs::create_directories(targets.directory);
  };

  // The frames that (b) writes, captured once, untimed.
  std::vector<io::FrameData> frames;
  {
    std::unique_ptr<tickfx::ParticleSystem> system = start();
    simulate(*system, [&](io::FrameData data) { frames.push_back(std::move(data)); });
    end(*system);
  }
  freshFolder();
  io::writeFrameCaches(frames.front(), targets);
  double bytes = 0.0;
  for (const fs::directory_entry& e : fs::directory_iterator(targets.directory))
    bytes += static_cast<double>(e.file_size());
  std::printf("  %s: %zu particles, %.1f MB of cache a frame\n", row.format.c_str(),
              frames.front().size(), bytes / 1e6);
  std::fflush(stdout);

  const auto measure = [](Rounds& into, auto&& body) {
    const double cpu0 = bench::processCpuSeconds();
    const auto t0 = bench::Clock::now();
    body();
    into.wall.push_back(Seconds(bench::Clock::now() - t0).count());
    into.cpu.push_back(bench::processCpuSeconds() - cpu0);
  };
  for (int r = 0; r < rounds; ++r) {
    {  // (a) simulation and capture only
      std::unique_ptr<tickfx::ParticleSystem> system = start();
      measure(row.simulate, [&] {
        simulate(*system, [](io::FrameData data) { bench::escape(data.id.data()); });
      });
      end(*system);
    }
    freshFolder();  // (b) writing only
    measure(row.write, [&] {
      for (const io::FrameData& data : frames) io::writeFrameCaches(data, targets);
    });
    for (const bool overlapped : {true, false}) {  // (c) and (d)
      std::unique_ptr<tickfx::ParticleSystem> system = start();
      freshFolder();
      io::BackgroundWriter writer(
          [&targets](const io::FrameData& data) { io::writeFrameCaches(data, targets); },
          overlapped);
      measure(overlapped ? row.overlapped : row.inlined, [&] {
        simulate(*system, [&](io::FrameData data) { writer.submit(std::move(data)); });
        writer.finish();
      });
      (overlapped ? row.writeSecondsOverlapped : row.writeSecondsInline) +=
          writer.writeSeconds() / rounds;
      end(*system);
      const auto files =
          std::distance(fs::directory_iterator(targets.directory), fs::directory_iterator());
      same = same && files == kTimedFrames;
    }
  }
  fs::remove_all(targets.directory);
  rows.push_back(std::move(row));
  return same;
}

void printOverlap(const std::vector<OverlapRow>& rows, int rounds, int threads) {
  std::printf(
      "\noverlap: wall s for %d frames (median of %d rounds): (a) simulate + capture, (b) write, "
      "(c) both with the BackgroundWriter overlapped, (d) not overlapped\n",
      kTimedFrames, rounds);
  std::printf("%-6s %9s %9s %9s %9s %9s %9s %14s %7s %5s %9s  %s\n", "format", "N", "(a) sim",
              "(b) write", "a + b", "(c) over", "(d) inl.", "c / max(a,b)", "target", "met",
              "gain d/c", "writer's own s in (c), (d)");
  for (const OverlapRow& r : rows) {
    const double a = bench::median(r.simulate.wall), b = bench::median(r.write.wall);
    const double c = bench::median(r.overlapped.wall), d = bench::median(r.inlined.wall);
    const double ratio = c / std::max(a, b);
    std::printf("%-6s %9.0e %9.3f %9.3f %9.3f %9.3f %9.3f %14.3f %7s %5s %9.2f  %.3f, %.3f\n",
                r.format.c_str(), static_cast<double>(r.n), a, b, a + b, c, d, ratio, "<=1.15",
                ratio <= 1.15 ? "yes" : "NO", d / c, r.writeSecondsOverlapped,
                r.writeSecondsInline);
  }
  // Overlap hides a wait, not work: when (a) and (b) each keep every core busy, (c) cannot beat
  // their CPU seconds over the cores, however well the writer overlaps.
  std::printf(
      "\noverlap, CPU s of all threads (median): the best (c) can be on %d cores is max(a, b, "
      "(cpu a + cpu b) / %d)\n",
      threads, threads);
  std::printf("%-6s %9s %9s %9s %9s %9s %12s %12s\n", "format", "N", "cpu (a)", "cpu (b)",
              "cpu (c)", "cpu (d)", "best (c)", "(c) / best");
  for (const OverlapRow& r : rows) {
    const double ca = bench::median(r.simulate.cpu), cb = bench::median(r.write.cpu);
    const double best = std::max(
        {bench::median(r.simulate.wall), bench::median(r.write.wall), (ca + cb) / threads});
    std::printf("%-6s %9.0e %9.3f %9.3f %9.3f %9.3f %12.3f %12.3f\n", r.format.c_str(),
                static_cast<double>(r.n), ca, cb, bench::median(r.overlapped.cpu),
                bench::median(r.inlined.cpu), best, bench::median(r.overlapped.wall) / best);
  }
}

// The summary, one line a figure (BenchHarness.h), from both parts' tables.
void printFigures(const Part1& p, const std::vector<OverlapRow>& overlap, int allThreads) {
  std::printf("\n");
  for (const ResultRow& r : p.rows) {
    std::string name = r.format + " " + bench::sizeLabel(r.n);
    if (r.threads != allThreads) name += " " + threadsLabel(r.threads);
    if (r.synced) name += " synced";
    // The targets are judged at 10⁶ on all threads with the default durability (printPart1).
    const bool judged = r.n == kTargetSize && r.threads == allThreads && !r.synced;
    const std::string where = judged ? "" : " at 1e6, " + threadsLabel(allThreads);
    std::printf(
        "cache %s: k = %.3g x dd%s (target <= %g%s), %s particles/s, %s MB/s (%.1f %% stolen)\n",
        name.c_str(), r.writer / r.dd, r.synced ? " with fsync" : "", r.target, where.c_str(),
        bench::g3(static_cast<double>(r.n) / r.writer).c_str(),
        bench::g3(r.bytes / 1e6 / r.writer).c_str(), 100.0 * r.stolen);
  }
  for (const OverlapRow& r : overlap) {
    const double a = bench::median(r.simulate.wall), b = bench::median(r.write.wall);
    const double c = bench::median(r.overlapped.wall), d = bench::median(r.inlined.wall);
    std::printf(
        "cache overlap %s %s: wall %.3g x max(sim, write) (target <= 1.15), gain %.2fx over "
        "inline\n",
        r.format.c_str(), bench::sizeLabel(r.n).c_str(), c / std::max(a, b), d / c);
  }
}

// ---- the run ----------------------------------------------------------------------------------

void usage(const char* argv0) {
  std::printf(
      "usage: %s [--quick] [--sizes=N[,N...]] [--overlap=N] [--rounds=COUNT] [--dir=PATH]\n"
      "          [--min-time=SECONDS] [--reps=COUNT]\n"
      "  --quick            smoke run: sizes 1e4,1e5, overlap 1e5, --min-time=0.02, 2 rounds\n"
      "  --sizes=1e4,1e6    particle counts of the writers against dd (default 1e4,1e6,1e7)\n"
      "  --overlap=1e6      particles of the overlap part (default 1e6; 0 skips it)\n"
      "  --rounds=3         runs of each overlap case (the median is reported)\n"
      "  --dir=PATH         write in a fresh folder inside PATH (default /tmp); removed after\n"
      "  --min-time=0.3     seconds each writer case is timed, per format and size\n"
      "  --reps=5           minimum number of timed batches per case (the median is reported)\n",
      argv0);
}

double freeBytes(const fs::path& dir) {
  struct statvfs s {};
  if (::statvfs(dir.c_str(), &s) != 0) return 0.0;
  return static_cast<double>(s.f_bavail) * static_cast<double>(s.f_frsize);
}

double memoryBytes() {
  return static_cast<double>(::sysconf(_SC_PHYS_PAGES)) *
         static_cast<double>(::sysconf(_SC_PAGE_SIZE));
}

int run(int argc, char** argv) {
  std::optional<std::vector<std::size_t>> sizes;
  std::optional<std::size_t> overlap, rounds;
  std::optional<std::string> dirGiven;
  bench::CommandLine cl(usage);
  cl.sizes("--sizes", sizes)
      .count("--overlap", overlap)
      .count("--rounds", rounds, [](std::size_t r) { return r >= 1 && r <= INT_MAX; })
      .text("--dir", dirGiven);
  if (const std::optional<int> exitCode = cl.parse(argc, argv)) return *exitCode;
  const fs::path parent = dirGiven ? fs::path(*dirGiven) : fs::temp_directory_path();
  std::vector<std::size_t> writerSizes{10'000, 1'000'000, 10'000'000};
  std::size_t overlapSize = 1'000'000;
  int overlapRounds = 3;
  if (cl.quick) {
    writerSizes = {10'000, 100'000};
    overlapSize = 100'000;
    overlapRounds = 2;
  }
  if (sizes) writerSizes = *sizes;
  if (overlap) overlapSize = *overlap;
  if (rounds) overlapRounds = static_cast<int>(*rounds);

  const int allThreads = tbb::info::default_concurrency();
  std::printf("cache_bench: cache writers against dd, and writing overlapped with simulating\n");
  char machine[64];
  std::snprintf(machine, sizeof machine, " (TBB uses %d), %.1f GB of memory", allThreads,
                memoryBytes() / 1e9);
  bench::printMachine(machine);
  bench::printBuild();

  std::error_code ec;
  if (!fs::is_directory(parent, ec)) {
    std::fprintf(stderr, "cache_bench: %s is not a folder\n", parent.c_str());
    return 2;
  }
  // Each part-1 file exists beside its temporary and the other case's file; an overlap case
  // holds its 12 frames (CSV, the larger format) and the next one's temporary.
  double largest = 0.0;
  for (const std::size_t n : writerSizes) largest = std::max(largest, estimateLargestFile(n));
  const double overlapBytes =
      overlapSize > 0 ? (kTimedFrames + 1) * estimateCsvBytes(overlapSize) : 0.0;
  const double needed = std::max(3.0 * largest, overlapBytes);
  const double available = freeBytes(parent);
  std::printf("folder: %s, %.1f GB free; largest file about %.3f GB, %.1f GB needed\n",
              parent.c_str(), available / 1e9, largest / 1e9, needed / 1e9);
  if (available < needed) {
    std::fprintf(stderr,
                 "cache_bench: %s has %.2f GB free, less than the %.2f GB this run needs (3 times "
                 "its largest file); give smaller --sizes or another --dir\n",
                 parent.c_str(), available / 1e9, needed / 1e9);
    return 2;
  }
  if (2.0 * largest > 0.2 * memoryBytes()) {
    std::printf(
        "note: two of the largest files pass a fifth of the memory: the kernel then writes back "
        "while the bench writes, and the figures fall towards the disk's speed\n");
  }

  std::string folder = (parent / "cache_bench-XXXXXX").string();
  if (::mkdtemp(folder.data()) == nullptr) {
    std::fprintf(stderr, "cache_bench: cannot make a folder in %s: %s\n", parent.c_str(),
                 std::strerror(errno));
    return 2;
  }
  const fs::path dir = folder;
  std::printf("writing in %s (removed at the end)\n", dir.c_str());

  bool ok = true;
  try {
    Part1 part1;
    for (const std::size_t n : writerSizes) {
      const bool reference = n == kTargetSize || (std::find(writerSizes.begin(), writerSizes.end(),
                                                            kTargetSize) == writerSizes.end() &&
                                                  n == writerSizes.back());
      const bench::Timing& timing = cl.timing;
      std::printf("\nN = %zu (min-time %.2f s, at least %d batches a case)\n", n, timing.minTime,
                  timing.reps);
      std::fflush(stdout);
      const io::FrameData frame = syntheticFrame(n);
      for (const FormatInfo& f : kFormats)
        runFormat(f, frame, reference, dir, timing, allThreads, part1);
    }
    ok = part1.sizesAgree;
    printPart1(part1, allThreads);
    std::fflush(stdout);

    std::vector<OverlapRow> overlapRows;
    if (overlapSize > 0) {
      std::printf("\noverlap: a burst of %zu particles, gravity, 120 Hz, 24 fps, %d rounds\n",
                  overlapSize, overlapRounds);
      const io::LoadResult load = io::parseEffect(effectText(overlapSize), "bench.toml");
      if (!load.ok()) {
        for (const io::Diagnostic& d : load.diagnostics)
          std::fprintf(stderr, "%s\n", d.format().c_str());
        fs::remove_all(dir, ec);
        return 1;
      }
      bool same = true;
      for (const io::CacheFormat format : {io::CacheFormat::Ply, io::CacheFormat::Csv})
        same =
            runOverlap(format, *load.effect, overlapSize, overlapRounds, dir, overlapRows) && same;
      printOverlap(overlapRows, overlapRounds, allThreads);
      if (!same)
        std::printf("CHECK FAILED: the overlap cases did not all start and end in one state\n");
      ok = ok && same;
    }
    printFigures(part1, overlapRows, allThreads);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "cache_bench: %s\n", e.what());
    fs::remove_all(dir, ec);
    return 1;
  }
  fs::remove_all(dir, ec);
  return ok ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) { return run(argc, argv); }
