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

}  // namespace tickfx::io
