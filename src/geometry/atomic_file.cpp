#include "clod/atomic_file.h"

#include <atomic>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <unistd.h>

#include "clod/error.h"
#include "file_type_name.h"

namespace clod {

void writeFileAtomically(const std::filesystem::path& path, std::string_view content) {
  // The rename would replace whatever is at `path`: as root, `-o /dev/full` turned the device
  // into a regular file. Only a regular file (or a link to one) is ours to replace.
  std::error_code statusError;
  const auto status = std::filesystem::status(path, statusError);
  if (std::filesystem::exists(status) && !std::filesystem::is_regular_file(status)) {
    throw Error(ErrorCode::kFileWriteFailed, "refusing to replace '" + path.string() + "': it is " +
                                                 detail::fileTypeName(status.type()) + ", not a regular file");
  }
  // A temporary name of its own per call: two threads writing the same target (parallel scene
  // builds sharing a bake cache) each rename their own complete file into place.
  static std::atomic<std::uint64_t> writeCount{0};
  std::filesystem::path temp = path;
  temp += ".tmp." + std::to_string(::getpid()) + "." + std::to_string(writeCount.fetch_add(1));
  std::FILE* file = std::fopen(temp.c_str(), "wb");
  if (!file) throw Error(ErrorCode::kFileWriteFailed, "cannot open '" + temp.string() + "' for writing");
  const bool written = std::fwrite(content.data(), 1, content.size(), file) == content.size() &&
                       std::fflush(file) == 0 && ::fsync(::fileno(file)) == 0;
  const bool closed = std::fclose(file) == 0;
  std::error_code ec;
  if (!written || !closed) {
    std::filesystem::remove(temp, ec);
    throw Error(ErrorCode::kFileWriteFailed, "writing '" + path.string() + "' failed (disk full?)");
  }
  std::filesystem::rename(temp, path, ec);
  if (ec) {
    std::error_code removeError;
    std::filesystem::remove(temp, removeError);
    throw Error(ErrorCode::kFileWriteFailed, "cannot rename into '" + path.string() + "': " + ec.message());
  }
}

std::string readWholeFile(const std::filesystem::path& path) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (!std::filesystem::exists(status)) throw Error(ErrorCode::kFileNotFound, "'" + path.string() + "' does not exist");
  if (std::filesystem::is_directory(status)) throw Error(ErrorCode::kFileUnreadable, "'" + path.string() + "' is a directory");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(ErrorCode::kFileUnreadable, "cannot open '" + path.string() + "' for reading");
  std::string content((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw Error(ErrorCode::kFileUnreadable, "I/O error while reading '" + path.string() + "'");
  return content;
}

}  // namespace clod
