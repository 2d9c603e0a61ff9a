// Files that appear whole or not at all.
#pragma once

#include <filesystem>
#include <functional>
#include <ostream>

namespace tickfx::io {

/// Writes `path` through `write` into a temporary file beside it, then renames it into place, so
/// a reader (or a crash) never sees half a file. Throws std::runtime_error naming the path when
/// anything fails; the temporary is removed and an existing `path` is left untouched.
void writeFileAtomically(const std::filesystem::path& path,
                         const std::function<void(std::ostream&)>& write);

/// The same for writers that open files by name themselves (OpenVDB's io::File): `write` is
/// given the temporary's path, beside `path`, and must leave the whole file there or throw.
void writeFileAtomicallyByName(const std::filesystem::path& path,
                               const std::function<void(const std::filesystem::path&)>& write);

/// Checks, before anything is written, that `path` could be written atomically: its folder
/// exists and takes a new file, and `path` is not a folder. Throws std::runtime_error
/// "PATH: error: cannot write (REASON)" otherwise; leaves nothing behind.
void requireWritable(const std::filesystem::path& path);

}  // namespace tickfx::io
