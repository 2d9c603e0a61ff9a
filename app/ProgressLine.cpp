#include "app/ProgressLine.h"

#include <unistd.h>
#include <cstdio>

namespace tickfx::app {

ProgressLine::ProgressLine()
    : enabled_(::isatty(STDERR_FILENO) == 1), start_(Clock::now()), last_(start_) {}

ProgressLine::~ProgressLine() { finish(); }

void ProgressLine::update(std::int64_t frame, double simSeconds, double totalSeconds,
                          std::size_t particles) {
  if (!enabled_) return;
  const Clock::time_point now = Clock::now();
  if (now - start_ < std::chrono::seconds(1) || now - last_ < std::chrono::milliseconds(100))
    return;
  last_ = now;
  shown_ = true;
  std::fprintf(stderr, "\r\033[Kframe %lld  t = %.3f of %.3f s  particles: %zu",
               static_cast<long long>(frame), simSeconds, totalSeconds, particles);
  std::fflush(stderr);
}

void ProgressLine::finish() {
  if (!shown_) return;
  std::fprintf(stderr, "\r\033[K");
  std::fflush(stderr);
  shown_ = false;
}

}  // namespace tickfx::app
