// Ctrl-C and `kill` during a long command: finish the frame in hand, then stop cleanly.
#pragma once

namespace tickfx::app {

/// While alive, SIGINT and SIGTERM only set a flag (caught()) that the command polls between
/// frames, so that the frame in hand is finished and its files written whole before it stops.
/// A second signal of the same kind ends the process at once, as if none had been caught (each
/// handler resets on first use). The previous handlers are restored on destruction.
class InterruptCatcher {
 public:
  InterruptCatcher();
  ~InterruptCatcher();
  InterruptCatcher(const InterruptCatcher&) = delete;
  InterruptCatcher& operator=(const InterruptCatcher&) = delete;

  /// The signal caught (SIGINT or SIGTERM), or 0.
  static int caught();
  /// "SIGINT" or "SIGTERM".
  static const char* name(int signal);
};

}  // namespace tickfx::app
