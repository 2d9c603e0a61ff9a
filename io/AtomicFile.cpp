#include "io/AtomicFile.h"

#include <unistd.h>
#include <fstream>
#include <stdexcept>
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
  // The pid keeps two processes writing the same cache folder from sharing a temporary.
  std::filesystem::path temp = path;
  temp += ".tmp" + std::to_string(::getpid());
  try {
    write(temp);
    std::filesystem::rename(temp, path);
  } catch (...) {
    std::error_code ignored;
    std::filesystem::remove(temp, ignored);
    throw;
  }
}

}  // namespace tickfx::io
