#include "clod/atomic_directory.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <utility>
#include <vector>

#include "clod/error.h"
#include "file_type_name.h"

namespace clod {
namespace {

namespace fs = std::filesystem;

[[noreturn]] void fail(const fs::path& path, const std::string& what) {
  throw Error(ErrorCode::kFileWriteFailed, "'" + path.string() + "': " + what);
}

// fsync of a directory makes the names in it (the staging files, the exchange) durable.
void syncDirectory(const fs::path& dir) {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) fail(dir, std::string("cannot open to flush: ") + std::strerror(errno));
  const bool synced = ::fsync(fd) == 0;
  const int savedErrno = errno;
  ::close(fd);
  if (!synced) fail(dir, std::string("fsync failed: ") + std::strerror(savedErrno));
}

// Every file below `dir`, then `dir`: what `write` wrote need not have been flushed.
void syncTree(const fs::path& dir) {
  for (const fs::directory_entry& entry : fs::recursive_directory_iterator(dir)) {
    if (!entry.is_regular_file()) continue;
    const int fd = ::open(entry.path().c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0 || ::fsync(fd) != 0) {
      const int savedErrno = errno;
      if (fd >= 0) ::close(fd);
      fail(entry.path(), std::string("fsync failed: ") + std::strerror(savedErrno));
    }
    ::close(fd);
  }
  syncDirectory(dir);
}

bool isOwned(const std::string& name, std::span<const std::string> ownedNames) {
  return std::any_of(ownedNames.begin(), ownedNames.end(), [&](const std::string& owned) {
    return name == owned || name.starts_with(owned + ".tmp.");  // a killed writeFileAtomically's leftover
  });
}

// `dir` as an absolute path with a file name ("out/" and "out/." name "out"), links followed.
fs::path normalisedDirectory(const fs::path& dir) {
  std::error_code ec;
  fs::path path = fs::absolute(dir, ec).lexically_normal();
  if (ec) fail(dir, "cannot resolve: " + ec.message());
  while (!path.has_filename() && path.has_parent_path() && path != path.root_path()) path = path.parent_path();
  if (fs::is_symlink(fs::symlink_status(path, ec))) {
    path = fs::canonical(path, ec);
    if (ec) fail(dir, "cannot follow the symbolic link: " + ec.message());
  }
  if (!path.has_filename() || path == path.root_path()) fail(dir, "cannot replace a root directory");
  return path;
}

}  // namespace

void checkOutputDirectory(const fs::path& dir) {
  std::error_code ec;
  const fs::file_status status = fs::status(dir, ec);
  if (fs::exists(status) && !fs::is_directory(status)) {
    fail(dir, std::string("refusing to use it as the output directory: it is ") + detail::fileTypeName(status.type()) +
                  ", not a directory");
  }
}

void replaceDirectoryAtomically(const fs::path& dirIn, std::span<const std::string> ownedNames,
                                const std::function<void(const fs::path& staging)>& write) {
  checkOutputDirectory(dirIn);
  const fs::path dir = normalisedDirectory(dirIn);
  const fs::path parent = dir.parent_path();
  std::error_code ec;
  fs::create_directories(parent, ec);
  if (ec) fail(parent, "cannot create directory: " + ec.message());
  // Hidden and named by the process: a second run's staging never meets this one's. A directory
  // of that name is a leftover of a killed process that had the same id.
  std::string stagingName = ".";  // appended: GCC 12 reports a false -Wrestrict on `"." + ...`
  stagingName += dir.filename().string();
  stagingName += ".tmp." + std::to_string(::getpid());
  const fs::path staging = parent / stagingName;
  fs::remove_all(staging, ec);
  if (!fs::create_directory(staging, ec) || ec) fail(staging, "cannot create the staging directory: " + ec.message());

  std::vector<std::string> moved;  // entries carried across, to move back on failure
  try {
    write(staging);
    syncTree(staging);  // before entries are carried across: only the new files need flushing
    const bool dirExists = fs::is_directory(dir, ec);
    if (dirExists) {
      for (const fs::directory_entry& entry : fs::directory_iterator(dir)) {
        const std::string name = entry.path().filename().string();
        if (isOwned(name, ownedNames) || fs::exists(fs::symlink_status(staging / name))) continue;
        fs::rename(entry.path(), staging / name, ec);
        if (ec) fail(entry.path(), "cannot move it into the staging directory: " + ec.message());
        moved.push_back(name);
      }
    }
    syncDirectory(staging);
    if (dirExists) {
      if (::renameat2(AT_FDCWD, staging.c_str(), AT_FDCWD, dir.c_str(), RENAME_EXCHANGE) != 0) {
        fail(dir, std::string("cannot exchange it with the staging directory: ") + std::strerror(errno));
      }
    } else if (::rename(staging.c_str(), dir.c_str()) != 0) {
      fail(dir, std::string("cannot rename the staging directory into place: ") + std::strerror(errno));
    }
  } catch (...) {
    bool allBack = true;
    for (const std::string& name : moved) {
      std::error_code back;
      fs::rename(staging / name, dir / name, back);
      allBack = allBack && !back;
    }
    std::error_code ignored;
    if (allBack) fs::remove_all(staging, ignored);  // else the user's entries stay there, not deleted
    throw;
  }
  syncDirectory(parent);
  // `staging` now names the old directory, which holds only owned entries.
  fs::remove_all(staging, ec);
}

}  // namespace clod
