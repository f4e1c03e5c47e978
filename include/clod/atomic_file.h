#pragma once
// Whole-file reads and crash-safe writes used by every clod file writer and reader.

#include <filesystem>
#include <string>
#include <string_view>

namespace clod {

/// Writes `content` to `path` through a temporary file in the same directory, flushed and then
/// renamed into place, so a crash or a full disk never leaves a half-written file at `path`.
/// An existing `path` that is not a regular file (or a symbolic link to one) -- a device such
/// as /dev/full, a directory, a pipe -- is left alone: kFileWriteFailed before anything is written.
/// Throws clod::Error(kFileWriteFailed) naming the path.
void writeFileAtomically(const std::filesystem::path& path, std::string_view content);

/// Reads a whole file. Throws clod::Error: kFileNotFound, kFileUnreadable (directories,
/// permissions, I/O errors).
std::string readWholeFile(const std::filesystem::path& path);

}  // namespace clod
