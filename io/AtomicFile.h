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

}  // namespace tickfx::io
