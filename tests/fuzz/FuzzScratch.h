// What the fuzzers share: the readers under test take paths, as tickfx itself calls them, so each
// input goes through a file first (in a directory of this process, removed at exit).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <system_error>

#include <unistd.h>

namespace tickfx::fuzz {

/// This process's scratch directory, made on first use.
inline const std::filesystem::path& scratchDirectory() {
  static const std::filesystem::path dir = [] {
    auto d = std::filesystem::temp_directory_path() / ("tickfx-fuzz-" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    std::atexit([] {
      std::error_code ignored;
      std::filesystem::remove_all(scratchDirectory(), ignored);
    });
    return d;
  }();
  return dir;
}

/// Writes `size` bytes to the scratch file `name` (replacing it) and returns its path.
inline std::filesystem::path writeScratch(const char* name, const std::uint8_t* data,
                                          std::size_t size) {
  const std::filesystem::path path = scratchDirectory() / name;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  if (!out.flush()) throw std::logic_error("fuzz: cannot write " + path.string());
  return path;
}

}  // namespace tickfx::fuzz
