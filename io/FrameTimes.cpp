#include "io/FrameTimes.h"

#include <charconv>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <stdexcept>
#include <string>

#include "particles/Random.h"

namespace tickfx::io {
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

std::vector<Flicks> fixedRateFrames(FrameRate rate, Flicks total) {
  const Flicks frame = frameDuration(rate);
  std::vector<Flicks> frames(static_cast<std::size_t>(total / frame), frame);
  if (total % frame != 0) frames.push_back(total % frame);
  return frames;
}

std::vector<Flicks> fixedRateFrameCount(FrameRate rate, std::int64_t count) {
  return std::vector<Flicks>(static_cast<std::size_t>(std::max<std::int64_t>(count, 0)),
                             frameDuration(rate));
}

std::vector<Flicks> jitteredFrames(std::uint64_t seed, Flicks total) {
  constexpr Flicks kShortest = kFlicksPerSecond / 240;
  constexpr Flicks kLongest = kFlicksPerSecond / 10;
  std::vector<Flicks> frames;
  Flicks sum = 0;
  for (std::uint64_t i = 0; sum < total; ++i) {
    // The frame index is the serial: the sequence is a pure function of the seed, like emission.
    const std::uint64_t bits = randomBits(RandomKey{seed, 0xF4A3E5u, i, 0});
    const Flicks d = kShortest + static_cast<Flicks>(
                                     bits % static_cast<std::uint64_t>(kLongest - kShortest + 1));
    frames.push_back(std::min(d, total - sum));
    sum += frames.back();
  }
  return frames;
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

}  // namespace tickfx::io
