#include "app/FrameTimes.h"

#include <charconv>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <stdexcept>
#include <string>

#include "io/effect/EffectSettings.h"
#include "particles/Random.h"

namespace tickfx::app {
namespace {

bool parsePositive(std::string_view text, std::int64_t& value) {
  if (text.empty()) return false;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  return ec == std::errc() && end == text.data() + text.size() && value > 0;
}

}  // namespace

FrameRate parseFrameRate(std::string_view text) {
  FrameRate rate;
  const std::size_t slash = text.find('/');
  const bool ok = slash == std::string_view::npos
                      ? parsePositive(text, rate.numerator)
                      : parsePositive(text.substr(0, slash), rate.numerator) &&
                            parsePositive(text.substr(slash + 1), rate.denominator);
  if (!ok) {
    throw std::invalid_argument("frame rate '" + std::string(text) +
                                "' is not a positive integer or a ratio N/D such as 30000/1001");
  }
  frameDuration(rate);  // throws for rates whose frames are not whole flicks
  return rate;
}

Flicks lengthOfFrames(FrameRate rate, std::int64_t count, const std::string& what) {
  const __int128 length =
      static_cast<__int128>(frameDuration(rate)) * std::max<std::int64_t>(count, 0);
  if (length > static_cast<__int128>(io::kMaxRunSeconds) * kFlicksPerSecond) {
    throw std::runtime_error(what + ": " + std::to_string(count) +
                             " frames last longer than 1e9 s (the longest run)");
  }
  return static_cast<Flicks>(length);
}

FrameSchedule FrameSchedule::fixedRate(FrameRate rate, Flicks total) {
  FrameSchedule s(Kind::Fixed, total);
  s.frame_ = frameDuration(rate);
  return s;
}

FrameSchedule FrameSchedule::jittered(std::uint64_t seed, Flicks total) {
  FrameSchedule s(Kind::Jittered, total);
  s.seed_ = seed;
  return s;
}

FrameSchedule FrameSchedule::recorded(std::vector<Flicks> frames) {
  Flicks total = 0;
  for (Flicks f : frames) total += f;
  FrameSchedule s(Kind::Recorded, total);
  s.list_ = std::move(frames);
  return s;
}

std::optional<Flicks> FrameSchedule::next() {
  Flicks d = 0;
  if (kind_ == Kind::Recorded) {
    if (index_ == static_cast<std::int64_t>(list_.size())) return std::nullopt;
    d = list_[static_cast<std::size_t>(index_)];
  } else {
    if (elapsed_ >= total_) return std::nullopt;
    if (kind_ == Kind::Fixed) {
      d = frame_;
    } else {
      constexpr Flicks kShortest = kFlicksPerSecond / 240;
      constexpr Flicks kLongest = kFlicksPerSecond / 10;
      // The frame index is the serial: the sequence is a pure function of the seed, like
      // emission.
      const std::uint64_t bits =
          randomBits(RandomKey{seed_, 0xF4A3E5u, static_cast<std::uint64_t>(index_), 0});
      d = kShortest +
          static_cast<Flicks>(bits % static_cast<std::uint64_t>(kLongest - kShortest + 1));
    }
    d = std::min(d, total_ - elapsed_);
  }
  elapsed_ += d;
  ++index_;
  return d;
}

namespace {

std::vector<Flicks> allFrames(FrameSchedule schedule) {
  std::vector<Flicks> frames;
  while (const std::optional<Flicks> d = schedule.next()) frames.push_back(*d);
  return frames;
}

}  // namespace

std::vector<Flicks> fixedRateFrames(FrameRate rate, Flicks total) {
  return allFrames(FrameSchedule::fixedRate(rate, total));
}

std::vector<Flicks> jitteredFrames(std::uint64_t seed, Flicks total) {
  return allFrames(FrameSchedule::jittered(seed, total));
}

std::vector<Flicks> readFrameTimes(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path.string() + ": cannot open frame-times file");
  std::vector<Flicks> frames;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    const std::size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    char* end = nullptr;
    const double seconds = std::strtod(line.c_str() + first, &end);
    const bool trailingOk =
        line.find_first_not_of(" \t\r", static_cast<std::size_t>(end - line.c_str())) ==
        std::string::npos;
    if (end == line.c_str() + first || !trailingOk || !std::isfinite(seconds) || seconds < 0.0 ||
        seconds > 3600.0) {
      throw std::runtime_error(path.string() + ":" + std::to_string(number) + ": error: '" + line +
                               "' is not a frame duration (seconds in [0, 3600])");
    }
    frames.push_back(flicksFromSeconds(seconds));
  }
  return frames;
}

}  // namespace tickfx::app
