#pragma once
// Crash-safe replacement of a command's output directory: the multi-file sibling of
// writeFileAtomically (atomic_file.h). Commands that write several files (simulate, mujoco,
// export) write them as one unit, so a kill or a failure never leaves old and new files mixed.

#include <filesystem>
#include <functional>
#include <span>
#include <string>

namespace clod {

/// Throws clod::Error(kFileWriteFailed) if `dir` exists and is not a directory (or a symbolic
/// link to one): a regular file, a device, a pipe is never replaced by an output directory.
/// Commands call it before their work, so the refusal comes at once.
void checkOutputDirectory(const std::filesystem::path& dir);

/// Replaces the files a command owns in the directory `dir` in one step. `write` writes the new
/// files into a fresh staging directory beside `dir` (DIR/../.NAME.tmp.<pid>). Then every entry
/// of the old `dir` that the command does not own -- a name not in `ownedNames` and not a
/// leftover "OWNED.tmp.*" of writeFileAtomically, nor one `write` just wrote -- is moved across
/// (bake-cache, the user's own files), the staging directory is flushed (fsync) and swapped with
/// `dir` by renameat2(RENAME_EXCHANGE) (a plain rename when `dir` does not exist yet), and the
/// old directory, now holding only owned entries, is removed. Owned names that `write` did not
/// write this time (scene.glb without --gltf) are dropped, not kept from an older run.
///
/// A kill at any point leaves `dir` with all old or all new owned files, never a mix; only a kill
/// while entries are moved across can leave some of them in the staging directory, named by
/// the process id. If `write` throws, or anything before the exchange fails, `dir` is untouched
/// (moved entries are moved back), the staging directory is removed and the exception
/// propagates. A symbolic link `dir` is followed: the directory it points to is replaced.
/// Throws clod::Error(kFileWriteFailed) naming the path (and as checkOutputDirectory).
void replaceDirectoryAtomically(const std::filesystem::path& dir, std::span<const std::string> ownedNames,
                                const std::function<void(const std::filesystem::path& staging)>& write);

}  // namespace clod
