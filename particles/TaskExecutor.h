// How a host lends its own threads to tickfx's parallel loops.
#pragma once

#include <cstddef>
#include <functional>

namespace tickfx {

/// A host's job system, seen by tickfx. Hosts that schedule their own threads (a game engine, a
/// renderer, a DCC's task pool) implement this and hand it to ParticleSystem::setTaskExecutor();
/// without one a system runs its loops in its own TBB arena.
///
/// The results never depend on the executor: the work is split into blocks by the particle
/// count alone (never by the number of workers), each block writes only its own rows, and no
/// result is reduced across blocks. Any executor, serial or parallel, gives the same bits.
class TaskExecutor {
 public:
  virtual ~TaskExecutor() = default;

  /// Runs `task(i)` once for every i in [0, count) and returns when every call has returned.
  /// The calls may run in any order, concurrently, on any threads (the calling one included).
  /// tickfx calls this from the thread driving the system, never re-entrantly from inside a
  /// task; tasks do not throw.
  virtual void run(std::size_t count, const std::function<void(std::size_t)>& task) = 0;
};

/// Runs every task on the calling thread, in index order: for hosts that want tickfx to use no
/// thread of its own, and for tests.
class SerialExecutor final : public TaskExecutor {
 public:
  void run(std::size_t count, const std::function<void(std::size_t)>& task) override {
    for (std::size_t i = 0; i < count; ++i) task(i);
  }
};

}  // namespace tickfx
