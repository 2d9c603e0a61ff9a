#include "io/util/AtomicFile.h"

#include <fcntl.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <streambuf>
#include <string>
#include <system_error>

namespace tickfx::io {
namespace {

// std::ofstream reports a failed write as a bit, without its cause: this buffer writes to a file
// descriptor itself and keeps the first errno, so the message can say "No space left on device".
class CheckedFileBuffer final : public std::streambuf {
 public:
  explicit CheckedFileBuffer(int fd) : fd_(fd) { resetPut(); }
  int error() const { return error_; }
  std::size_t written() const { return written_; }

 protected:
  int_type overflow(int_type c) override {
    if (drain() != 0) return traits_type::eof();
    if (!traits_type::eq_int_type(c, traits_type::eof())) {
      *pptr() = traits_type::to_char_type(c);
      pbump(1);
    }
    return traits_type::not_eof(c);
  }
  int sync() override { return drain(); }
  // A block as large as the buffer goes to the file as it is (copying megabytes of a cache
  // through 64 KiB would cost a pass over them for nothing), at an offset that is a multiple of
  // kAlign: the buffer is topped up to the boundary with the block's first bytes and written,
  // then the block's whole kAlign stretches, and its last bytes stay in the buffer. A page cache
  // of large folios (Linux 6.x, ext4) copies a write into a new file faster when it starts on
  // such a boundary (docs/performance.md): a cache's header would otherwise put every block of
  // its body off it.
  std::streamsize xsputn(const char* s, std::streamsize n) override {
    if (n < static_cast<std::streamsize>(buffer_.size())) return std::streambuf::xsputn(s, n);
    const auto size = static_cast<std::size_t>(n);
    const auto pending = static_cast<std::size_t>(pptr() - pbase());
    std::size_t head = (kAlign - (written_ + pending) % kAlign) % kAlign;
    if (pending + head <= buffer_.size()) {
      std::memcpy(pptr(), s, head);
      pbump(static_cast<int>(head));
      if (drain() != 0) return 0;
    } else {  // (after a flush that left the file off a boundary)
      if (drain() != 0) return 0;
      head = (kAlign - written_ % kAlign) % kAlign;
      if (writeAll(s, s + head) != 0) return 0;
    }
    const std::size_t whole = (size - head) / kAlign * kAlign;
    if (writeAll(s + head, s + head + whole) != 0) return 0;
    const std::size_t tail = size - head - whole;
    std::memcpy(pptr(), s + head + whole, tail);
    pbump(static_cast<int>(tail));
    return n;
  }

 private:
  int writeAll(const char* p, const char* end) {
    if (error_ != 0) return -1;
    while (p < end) {
      const ssize_t n = ::write(fd_, p, static_cast<std::size_t>(end - p));
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) {
        error_ = n < 0 ? errno : EIO;
        return -1;
      }
      p += n;
      written_ += static_cast<std::size_t>(n);
    }
    return 0;
  }
  int drain() {
    if (writeAll(pbase(), pptr()) != 0) return -1;
    resetPut();
    return 0;
  }
  void resetPut() { setp(buffer_.data(), buffer_.data() + buffer_.size()); }

  static constexpr std::size_t kAlign = std::size_t{1} << 16;

  int fd_;
  int error_ = 0;
  std::size_t written_ = 0;          // bytes written to the file
  std::array<char, kAlign> buffer_;  // (as large as kAlign: a topped-up buffer ends on a boundary)
};

// The directory entry of a rename reaches the disk with an fsync of the directory itself.
void syncDirectory(const std::filesystem::path& path) {
  const std::filesystem::path dir = path.has_parent_path() ? path.parent_path() : ".";
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) throw WriteError(path, std::strerror(errno));
  const int rc = ::fsync(fd);
  const int error = errno;
  ::close(fd);
  // Some filesystems cannot sync a directory (EINVAL): the rename is then as durable as they go.
  if (rc != 0 && error != EINVAL) throw WriteError(path, std::strerror(error));
}

void writeTemporary(const std::filesystem::path& path, const std::filesystem::path& temp,
                    const std::function<void(std::ostream&)>& write, Durability durability,
                    std::size_t expectedBytes) {
  const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd < 0) throw WriteError(path, std::strerror(errno));
  // The blocks of the whole file allocated at once: each 4 KiB block of a write into a file
  // without them is reserved on its own (ext4's delayed allocation), which cost a 46 MB cache's
  // write() some 0.7 ms of its 9 (docs/performance.md). A hint: a filesystem that cannot
  // (EOPNOTSUPP) or a disk without the room (ENOSPC) is left to the writes, whose errors are
  // reported.
  if (expectedBytes > 0) {
    [[maybe_unused]] const int ignored =
        ::fallocate(fd, FALLOC_FL_KEEP_SIZE, 0, static_cast<off_t>(expectedBytes));
  }
  CheckedFileBuffer buffer(fd);
  std::ostream out(&buffer);
  int error = 0;
  try {
    write(out);
    out.flush();
    error = buffer.error();
    if (error == 0 && !out) error = EIO;
    // Blocks allocated past what was written stay the file's (fallocate() keeps them): given
    // back by a truncation to its size.
    if (error == 0 && expectedBytes > buffer.written() &&
        ::ftruncate(fd, static_cast<off_t>(buffer.written())) != 0) {
      error = errno;
    }
    if (error == 0 && durability == Durability::Synced && ::fsync(fd) != 0) error = errno;
  } catch (...) {
    ::close(fd);
    throw;
  }
  // close() can report what the kernel could not write back (NFS, some full filesystems).
  if (::close(fd) != 0 && error == 0) error = errno;
  if (error != 0) throw WriteError(path, std::strerror(error));
}

}  // namespace

WriteError::WriteError(const std::filesystem::path& path, const std::string& reason,
                       const std::filesystem::path& leftover, const std::string& leftoverReason)
    : std::runtime_error(path.string() + ": error: cannot write (" + reason + ")" +
                         (leftover.empty() ? std::string()
                                           : "\n" + leftover.string() + ": error: cannot remove (" +
                                                 leftoverReason + ")")),
      path_(path),
      reason_(reason),
      leftover_(leftover) {}

void writeFileAtomically(const std::filesystem::path& path,
                         const std::function<void(std::ostream&)>& write, Durability durability,
                         std::size_t expectedBytes) {
  // The pid keeps two processes writing the same cache folder from sharing a temporary, and the
  // call count two threads of one process writing the same path.
  static std::atomic<std::uint64_t> calls{0};
  std::filesystem::path temp = path;
  temp += ".tmp" + std::to_string(::getpid()) + "-" + std::to_string(calls.fetch_add(1));
  try {
    writeTemporary(path, temp, write, durability, expectedBytes);
    std::error_code ec;
    std::filesystem::rename(temp, path, ec);
    if (ec) throw WriteError(path, ec.message());
  } catch (const WriteError& e) {
    std::error_code removed;
    std::filesystem::remove(temp, removed);
    if (removed && std::filesystem::exists(temp)) {
      throw WriteError(e.path(), e.reason(), temp, removed.message());
    }
    throw;
  } catch (...) {
    std::error_code ignored;
    std::filesystem::remove(temp, ignored);
    throw;
  }
  if (durability == Durability::Synced) syncDirectory(path);
}

void requireWritable(const std::filesystem::path& path) {
  auto fail = [&](const std::string& why) { throw WriteError(path, why); };
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) fail("it is a directory");
  const std::filesystem::path dir = path.has_parent_path() ? path.parent_path() : ".";
  if (!std::filesystem::is_directory(dir, ec)) fail("no directory " + dir.string());
  // The writers create a temporary beside the file and rename it: try exactly that permission.
  std::string probe = (dir / ".tickfx-probe-XXXXXX").string();
  const int fd = ::mkstemp(probe.data());
  if (fd < 0) fail(std::strerror(errno));
  ::close(fd);
  std::filesystem::remove(probe, ec);
}

}  // namespace tickfx::io
