// Files that appear whole or not at all.
#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <ostream>
#include <stdexcept>
#include <string>

namespace tickfx::io {

/// A file that could not be written. what() reads "PATH: error: cannot write (REASON)", REASON
/// being the system's ("No space left on device", "Permission denied", "File too large").
/// When the temporary beside the file could not be removed either (its directory was made
/// read-only meanwhile), a second line names it: "TEMP: error: cannot remove (REASON)".
class WriteError : public std::runtime_error {
 public:
  WriteError(const std::filesystem::path& path, const std::string& reason,
             const std::filesystem::path& leftover = {}, const std::string& leftoverReason = {});
  /// The file as the caller named it (never the temporary beside it).
  const std::filesystem::path& path() const { return path_; }
  const std::string& reason() const { return reason_; }
  /// The temporary left behind, or empty.
  const std::filesystem::path& leftover() const { return leftover_; }

 private:
  std::filesystem::path path_;
  std::string reason_;
  std::filesystem::path leftover_;
};

/// How far writeFileAtomically() goes before it returns.
enum class Durability {
  /// Renamed into place: every reader sees the whole file or the old one, and a crash of the
  /// process cannot change that. A power loss may still lose the newest files (the kernel writes
  /// them back later).
  Renamed,
  /// Also flushed to the disk (fsync of the file before the rename and of its directory after):
  /// after a power loss the path holds the old file or the new one, whole.
  Synced,
};

/// Writes `path` through `write` into a temporary file beside it, then renames it into place, so
/// a reader (or a crash) never sees half a file. Every write is checked: on any failure (a full
/// disk, a file size limit, a directory removed or made read-only meanwhile) throws WriteError
/// naming `path` and the system's reason; the temporary is removed and an existing `path` is left
/// untouched (if the temporary cannot be removed either, WriteError::leftover() names it).
/// Whatever `write` throws is passed on, with the same clean-up. `expectedBytes`, when known
/// (not 0): the bytes `write` will write, whose blocks are allocated at once where the
/// filesystem can (fallocate(); the file's size is what was written, and blocks allocated past
/// it are given back).
void writeFileAtomically(const std::filesystem::path& path,
                         const std::function<void(std::ostream&)>& write,
                         Durability durability = Durability::Renamed,
                         std::size_t expectedBytes = 0);

/// Checks, before anything is written, that `path` could be written atomically: its folder
/// exists and takes a new file, and `path` is not a folder. Throws WriteError otherwise; leaves
/// nothing behind.
void requireWritable(const std::filesystem::path& path);

}  // namespace tickfx::io
