#include "app/Interrupt.h"

#include <unistd.h>

#include <csignal>

namespace tickfx::app {
namespace {

volatile std::sig_atomic_t gCaught = 0;
struct sigaction gPreviousInt {};
struct sigaction gPreviousTerm {};

extern "C" void onInterrupt(int signal) {
  gCaught = signal;
  // write(2) is async-signal-safe; stdio is not.
  static const char kNote[] =
      "\ntickfx: stopping after the frame in hand (a second Ctrl-C stops at once)\n";
  [[maybe_unused]] const ssize_t ignored = ::write(STDERR_FILENO, kNote, sizeof kNote - 1);
}

}  // namespace

InterruptCatcher::InterruptCatcher() {
  gCaught = 0;
  struct sigaction action {};
  action.sa_handler = onInterrupt;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESETHAND;  // the second signal takes the default action: the process ends
  sigaction(SIGINT, &action, &gPreviousInt);
  sigaction(SIGTERM, &action, &gPreviousTerm);
}

InterruptCatcher::~InterruptCatcher() {
  sigaction(SIGINT, &gPreviousInt, nullptr);
  sigaction(SIGTERM, &gPreviousTerm, nullptr);
}

int InterruptCatcher::caught() { return gCaught; }

const char* InterruptCatcher::name(int signal) { return signal == SIGTERM ? "SIGTERM" : "SIGINT"; }

}  // namespace tickfx::app
