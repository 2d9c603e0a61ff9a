// A full disk, made to order: while a FileSizeLimit lives, no file this process writes can grow
// past its limit (RLIMIT_FSIZE, which binds root too), and a write past it fails with EFBIG
// ("File too large") instead of raising SIGXFSZ, which would kill the test. Both are restored
// when it ends. Process-wide: only for tests that run alone in their process.
#pragma once

#include <sys/resource.h>

#include <csignal>

namespace tickfx::test {

class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    if (::getrlimit(RLIMIT_FSIZE, &saved_) != 0) return;
    savedHandler_ = std::signal(SIGXFSZ, SIG_IGN);  // a short write, not a kill
    rlimit limited = saved_;
    limited.rlim_cur = bytes;
    set_ = ::setrlimit(RLIMIT_FSIZE, &limited) == 0;
  }
  ~FileSizeLimit() {
    if (set_) ::setrlimit(RLIMIT_FSIZE, &saved_);
    if (savedHandler_ != SIG_ERR) std::signal(SIGXFSZ, savedHandler_);
  }
  FileSizeLimit(const FileSizeLimit&) = delete;
  FileSizeLimit& operator=(const FileSizeLimit&) = delete;

  /// Whether the limit is in force (a test asserts it before writing).
  bool set() const { return set_; }

 private:
  rlimit saved_{};
  void (*savedHandler_)(int) = SIG_ERR;
  bool set_ = false;
};

}  // namespace tickfx::test
