// A flag that parallel loops raise and the caller reads once they have joined.
#pragma once

#include <atomic>

namespace tickfx {

/// A flag threads may set at once (relaxed: read only after the parallel loop that sets it has
/// joined). Copyable, so the pool stays a value.
class RelaxedFlag {
 public:
  RelaxedFlag() = default;
  RelaxedFlag(const RelaxedFlag& other) : value_(other.get()) {}
  RelaxedFlag& operator=(const RelaxedFlag& other) {
    value_.store(other.get(), std::memory_order_relaxed);
    return *this;
  }
  bool get() const { return value_.load(std::memory_order_relaxed); }
  /// Sets it, without writing the shared line when it is set already.
  void raise() {
    if (!get()) value_.store(true, std::memory_order_relaxed);
  }
  void clear() { value_.store(false, std::memory_order_relaxed); }

 private:
  std::atomic<bool> value_{false};
};

}  // namespace tickfx
