#include "app/ProgressLine.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace tickfx::app {
namespace {

constexpr int kBarWidth = 24;

// "7.5 s", "3 min 05 s", "2 h 07 min": the time left as a person reads it.
std::string duration(double seconds) {
  char text[48];
  if (seconds < 60.0) {
    std::snprintf(text, sizeof text, "%.1f s", seconds);
  } else if (seconds < 3600.0) {
    const auto s = static_cast<long long>(seconds);
    std::snprintf(text, sizeof text, "%lld min %02lld s", s / 60, s % 60);
  } else {
    const auto m = static_cast<long long>(seconds / 60.0);
    std::snprintf(text, sizeof text, "%lld h %02lld min", m / 60, m % 60);
  }
  return text;
}

}  // namespace

std::string progressText(std::int64_t done, std::int64_t total, double fraction,
                         double elapsedSeconds, std::string_view unit, std::string_view detail) {
  fraction = std::clamp(std::isfinite(fraction) ? fraction : 0.0, 0.0, 1.0);
  const int filled = static_cast<int>(std::lround(fraction * kBarWidth));
  std::string line = "[";
  for (int i = 0; i < kBarWidth; ++i) {
    line += i + 1 < filled ? '=' : (i + 1 == filled ? (filled == kBarWidth ? '=' : '>') : ' ');
  }
  line += "] " + std::to_string(done);
  if (total > 0) line += "/" + std::to_string(total);
  line += " ";
  line += unit;
  if (elapsedSeconds > 0.0) {
    char rate[64];
    std::snprintf(rate, sizeof rate, "  %.1f %.*s/s", static_cast<double>(done) / elapsedSeconds,
                  static_cast<int>(unit.size()), unit.data());
    line += rate;
    if (fraction > 0.0)
      line += "  " + duration(elapsedSeconds * (1.0 - fraction) / fraction) + " left";
  }
  if (!detail.empty()) {
    line += "  ";
    line += detail;
  }
  return line;
}

ProgressLine::ProgressLine(std::string unit)
    : unit_(std::move(unit)),
      enabled_(::isatty(STDERR_FILENO) == 1),
      start_(Clock::now()),
      last_(start_) {}

ProgressLine::~ProgressLine() { finish(); }

void ProgressLine::update(std::int64_t done, std::int64_t total, double fraction,
                          std::string_view detail) {
  if (!enabled_) return;
  const Clock::time_point now = Clock::now();
  if (now - start_ < std::chrono::seconds(1) ||
      (shown_ && now - last_ < std::chrono::milliseconds(100))) {
    return;
  }
  last_ = now;
  shown_ = true;
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  std::fprintf(stderr, "\r\033[K%s",
               progressText(done, total, fraction, elapsed, unit_, detail).c_str());
  std::fflush(stderr);
}

void ProgressLine::finish() {
  if (!shown_) return;
  std::fprintf(stderr, "\r\033[K");
  std::fflush(stderr);
  shown_ = false;
}

}  // namespace tickfx::app
