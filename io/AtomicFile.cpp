#include "io/AtomicFile.h"

#include <unistd.h>
#include <atomic>
#include <cerrno>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <string>
#include <system_error>

namespace tickfx::io {

void writeFileAtomically(const std::filesystem::path& path,
                         const std::function<void(std::ostream&)>& write) {
  writeFileAtomicallyByName(path, [&](const std::filesystem::path& temp) {
    std::ofstream out(temp, std::ios::binary | std::ios::trunc);
    if (!out) throw std::runtime_error("cannot create " + temp.string());
    write(out);
    out.flush();
    if (!out) throw std::runtime_error("cannot write " + temp.string());
  });
}

void writeFileAtomicallyByName(const std::filesystem::path& path,
                               const std::function<void(const std::filesystem::path&)>& write) {
  // The pid keeps two processes writing the same cache folder from sharing a temporary, and the
  // call count two threads of one process writing the same path.
  static std::atomic<std::uint64_t> calls{0};
  std::filesystem::path temp = path;
  temp += ".tmp" + std::to_string(::getpid()) + "-" + std::to_string(calls.fetch_add(1));
  try {
    write(temp);
    std::filesystem::rename(temp, path);
  } catch (...) {
    std::error_code ignored;
    std::filesystem::remove(temp, ignored);
    throw;
  }
}

void requireWritable(const std::filesystem::path& path) {
  auto fail = [&](const std::string& why) {
    throw std::runtime_error(path.string() + ": error: cannot write (" + why + ")");
  };
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
