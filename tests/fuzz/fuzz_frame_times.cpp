// libFuzzer target: app::readFrameTimes, the reader of `--frame-times FILE` (one frame length a
// line). Any input must give frame times or the reader's std::runtime_error, nothing else.
#include <cstddef>
#include <cstdint>
#include <stdexcept>

#include "FuzzScratch.h"
#include "app/FrameTimes.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = tickfx::fuzz::writeScratch("frames.txt", data, size);
  try {
    const auto frames = tickfx::app::readFrameTimes(path);
    for (const auto f : frames) {
      if (f < 0) __builtin_trap();  // a negative frame length was accepted
    }
  } catch (const std::runtime_error&) {
  }
  return 0;
}
