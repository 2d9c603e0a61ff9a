#include "io/state/HashLog.h"

#include <algorithm>
#include <charconv>
#include <cinttypes>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "io/util/AtomicFile.h"

namespace tickfx::io {
namespace {

constexpr const char* kHashLogMagic = "tickfx hash log 1";

std::string hex16(std::uint64_t v) {
  char text[17];
  std::snprintf(text, sizeof text, "%016" PRIx64, v);
  return text;
}

// Free text (a CPU's name) must stay on its line: the reader is line-based.
std::string oneLine(std::string text) {
  std::replace(text.begin(), text.end(), '\n', ' ');
  std::replace(text.begin(), text.end(), '\r', ' ');
  return text;
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> fields;
  std::istringstream in(line);
  for (std::string f; in >> f;) fields.push_back(f);
  return fields;
}

class HashLogReader {
 public:
  explicit HashLogReader(const std::filesystem::path& path) : path_(path), in_(path) {
    if (!in_) throw std::runtime_error(path_.string() + ": error: cannot read the hash log");
  }

  bool next() {
    if (!std::getline(in_, line_)) return false;
    ++number_;
    return true;
  }
  const std::string& line() const { return line_; }

  [[noreturn]] void fail(const std::string& what) const { failAt(number_, what); }
  [[noreturn]] void failAt(long line, const std::string& what) const {
    throw std::runtime_error(path_.string() + ":" + std::to_string(line) + ": error: " + what);
  }
  long number() const { return number_; }

  // The value of the header line `key: value`, which must come next.
  std::string header(const std::string& key) {
    if (!next()) failAt(number_ + 1, "the log ends in its header (expected '" + key + ": ...')");
    const std::string prefix = key + ": ";
    if (line_.rfind(prefix, 0) != 0) fail("expected '" + key + ": ...', found '" + line_ + "'");
    return line_.substr(prefix.size());
  }

  std::int64_t integer(const std::string& text, const std::string& what, std::int64_t min) const {
    std::int64_t v = 0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
    if (ec != std::errc() || end != text.data() + text.size() || v < min) {
      fail(what + ": '" + text + "' is not a whole number of at least " + std::to_string(min));
    }
    return v;
  }

  // `digits` == 16: a hash, exactly 16 hex digits; 0: 1 to 16 of them.
  std::uint64_t hex(const std::string& text, const std::string& what, int digits) const {
    std::uint64_t v = 0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v, 16);
    const bool widthOk = digits == 0 ? text.size() <= 16 : text.size() == std::size_t(digits);
    if (ec != std::errc() || end != text.data() + text.size() || !widthOk ||
        text.find_first_of("ABCDEF") != std::string::npos) {
      fail(what + ": '" + text + "' is not " +
           (digits == 0 ? std::string("1 to 16") : std::to_string(digits)) +
           " lowercase hex digits");
    }
    return v;
  }

 private:
  std::filesystem::path path_;
  std::ifstream in_;
  std::string line_;
  long number_ = 0;
};

}  // namespace

void writeHashLog(const std::filesystem::path& path, const HashLog& log) {
  const HashLogHeader& h = log.header;
  writeFileAtomically(path, [&](std::ostream& os) {
    os << kHashLogMagic << '\n';
    os << "machine: " << oneLine(h.machine) << '\n';
    os << "cpu: " << oneLine(h.cpu) << '\n';
    os << "compiler: " << oneLine(h.compiler) << '\n';
    os << "build: " << oneLine(h.build) << '\n';
    os << "tickfx: " << oneLine(h.version) << '\n';
    os << "effect: " << oneLine(h.effect) << '\n';
    os << "fingerprint: " << hex16(h.fingerprint) << '\n';
    os << "seed: " << h.seed << '\n';
    os << "step_rate: " << h.stepRateHz << '\n';
    os << "length_flicks: " << h.length << '\n';
    os << "fps: " << h.fps.numerator << '/' << h.fps.denominator << '\n';
    os << "frames: " << h.frames << '\n';
    os << "ticks: " << h.ticks << '\n';
    os << "columns:";
    for (const std::string& c : h.columns) os << ' ' << c;
    os << '\n';
    // Ticks, frames and snapshots in the order the run made them: a frame after the ticks it
    // covers, a snapshot after its tick.
    std::size_t frame = 0, snapshot = 0;
    auto flushAfter = [&](std::int64_t tick) {
      while (snapshot < log.snapshots.size() && log.snapshots[snapshot].tick <= tick) {
        const HashLogSnapshot& s = log.snapshots[snapshot++];
        os << "snapshot " << s.tick << ' ' << s.rows.size() << '\n';
        for (const auto& row : s.rows) {
          os << "row";
          for (std::size_t c = 0; c < row.size(); ++c) {
            char text[17];
            // id and birth tick are 64-bit; the float columns are 32 bits.
            std::snprintf(text, sizeof text, c < 2 ? "%016" PRIx64 : "%08" PRIx64, row[c]);
            os << ' ' << text;
          }
          os << '\n';
        }
      }
      while (frame < log.frames.size() && log.frames[frame].tick <= tick) {
        const HashLogFrame& f = log.frames[frame++];
        os << "frame " << f.frame << ' ' << f.tick << ' ' << hex16(f.hash) << '\n';
      }
    };
    flushAfter(0);
    for (const HashLogTick& t : log.ticks) {
      os << "tick " << t.tick << ' ' << hex16(t.state);
      for (std::uint64_t c : t.columns) os << ' ' << hex16(c);
      os << '\n';
      flushAfter(t.tick);
    }
    flushAfter(INT64_MAX);
    os << "end\n";
  });
}

HashLog readHashLog(const std::filesystem::path& path) {
  HashLogReader r(path);
  HashLog log;
  HashLogHeader& h = log.header;
  if (!r.next()) r.failAt(1, "the file is empty (expected '" + std::string(kHashLogMagic) + "')");
  if (r.line() != kHashLogMagic) {
    r.fail("not a tickfx hash log: '" + r.line() + "' (expected '" + kHashLogMagic + "')");
  }
  h.machine = r.header("machine");
  h.cpu = r.header("cpu");
  h.compiler = r.header("compiler");
  h.build = r.header("build");
  h.version = r.header("tickfx");
  h.effect = r.header("effect");
  h.fingerprint = r.hex(r.header("fingerprint"), "fingerprint", 16);
  h.seed = static_cast<std::uint64_t>(r.integer(r.header("seed"), "seed", 0));
  h.stepRateHz = r.integer(r.header("step_rate"), "step_rate", 1);
  h.length = r.integer(r.header("length_flicks"), "length_flicks", 0);
  const std::string fps = r.header("fps");
  const std::size_t slash = fps.find('/');
  if (slash == std::string::npos) r.fail("fps: '" + fps + "' is not N/D");
  h.fps = {r.integer(fps.substr(0, slash), "fps", 1), r.integer(fps.substr(slash + 1), "fps", 1)};
  h.frames = r.integer(r.header("frames"), "frames", 0);
  h.ticks = r.integer(r.header("ticks"), "ticks", 0);
  h.columns = split(r.header("columns"));
  if (h.columns.empty() || h.columns.front() != "counters") {
    r.fail("columns: expected the state's columns, starting with 'counters'");
  }
  const std::size_t columns = h.columns.size();

  bool ended = false;
  while (r.next()) {
    const std::vector<std::string> f = split(r.line());
    if (ended) r.fail("text after the 'end' line");
    const std::string kind = f.empty() ? "" : f[0];
    const std::int64_t lastTick = log.ticks.empty() ? 0 : log.ticks.back().tick;
    if (kind == "tick") {
      if (f.size() != 3 + columns) {
        r.fail("a tick line has " + std::to_string(f.size()) + " fields (expected 'tick N', " +
               "the state hash and " + std::to_string(columns) + " column hashes)");
      }
      HashLogTick t;
      t.tick = r.integer(f[1], "tick", 1);
      if (t.tick != lastTick + 1 || t.tick > h.ticks) {
        r.fail("tick " + f[1] + " out of order (expected tick " + std::to_string(lastTick + 1) +
               " of " + std::to_string(h.ticks) + ")");
      }
      t.state = r.hex(f[2], "tick " + f[1], 16);
      for (std::size_t c = 0; c < columns; ++c)
        t.columns.push_back(r.hex(f[3 + c], "tick " + f[1] + ", " + h.columns[c], 16));
      log.ticks.push_back(std::move(t));
    } else if (kind == "frame") {
      if (f.size() != 4)
        r.fail("a frame line has " + std::to_string(f.size()) +
               " fields (expected 'frame N TICK HASH')");
      HashLogFrame fr;
      fr.frame = r.integer(f[1], "frame", 1);
      const auto expected = static_cast<std::int64_t>(log.frames.size()) + 1;
      if (fr.frame != expected || fr.frame > h.frames) {
        r.fail("frame " + f[1] + " out of order (expected frame " + std::to_string(expected) +
               " of " + std::to_string(h.frames) + ")");
      }
      fr.tick = r.integer(f[2], "frame " + f[1] + ": tick", 0);
      if (fr.tick != lastTick) {
        r.fail("frame " + f[1] + " after tick " + f[2] + " follows tick " +
               std::to_string(lastTick) + " (expected the frame after its ticks)");
      }
      fr.hash = r.hex(f[3], "frame " + f[1], 16);
      log.frames.push_back(fr);
    } else if (kind == "snapshot") {
      if (f.size() != 3) r.fail("expected 'snapshot TICK ROWS'");
      HashLogSnapshot s;
      s.tick = r.integer(f[1], "snapshot", 0);
      if (s.tick != lastTick) {
        r.fail("snapshot of tick " + f[1] + " follows tick " + std::to_string(lastTick) +
               " (expected a snapshot right after its tick)");
      }
      const std::int64_t rows = r.integer(f[2], "snapshot: rows", 0);
      for (std::int64_t i = 0; i < rows; ++i) {
        if (!r.next()) {
          r.failAt(r.number() + 1, "the log ends in the snapshot of tick " + f[1] +
                                       " (truncated? expected " + f[2] + " rows)");
        }
        const std::vector<std::string> row = split(r.line());
        if (row.size() != columns || row[0] != "row") {
          r.fail("expected 'row' and " + std::to_string(columns - 1) +
                 " hex values (snapshot of tick " + f[1] + ")");
        }
        std::vector<std::uint64_t> bits;
        for (std::size_t c = 1; c < columns; ++c)
          bits.push_back(r.hex(row[c], "row, " + h.columns[c], 0));
        s.rows.push_back(std::move(bits));
      }
      log.snapshots.push_back(std::move(s));
    } else if (kind == "end" && f.size() == 1) {
      if (lastTick != h.ticks || static_cast<std::int64_t>(log.frames.size()) != h.frames) {
        r.fail("the log ends after " + std::to_string(lastTick) + " ticks and " +
               std::to_string(log.frames.size()) + " frames (expected " + std::to_string(h.ticks) +
               " ticks and " + std::to_string(h.frames) + " frames)");
      }
      ended = true;
    } else {
      r.fail("unknown line '" + r.line() + "' (expected tick, frame, snapshot or end)");
    }
  }
  if (!ended) {
    r.failAt(r.number() + 1, "the log ends without its 'end' line (truncated? " +
                                 std::to_string(log.ticks.size()) + " of " +
                                 std::to_string(h.ticks) + " ticks)");
  }
  return log;
}

}  // namespace tickfx::io
