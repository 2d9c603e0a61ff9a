#include "particles/Assert.h"

#include <atomic>
#include <cstdio>
#include <cstdlib>

namespace tickfx {
namespace {

void printFailure(const AssertFailure& f) {
  std::fprintf(stderr, "%s:%d: tickfx assertion failed: %s (%s)\n", f.file, f.line, f.condition,
               f.message);
}

std::atomic<AssertHook> gHook{printFailure};

}  // namespace

AssertHook setAssertHook(AssertHook hook) noexcept {
  return gHook.exchange(hook != nullptr ? hook : printFailure);
}

void assertFailed(const AssertFailure& failure) {
  gHook.load()(failure);
  std::abort();
}

}  // namespace tickfx
