#pragma once
// The kind of a file system entry in words, for the output writers' refusals
// ("refusing to replace '/dev/full': it is a character device").

#include <filesystem>

namespace clod::detail {

inline const char* fileTypeName(std::filesystem::file_type type) {
  switch (type) {
    case std::filesystem::file_type::regular: return "a regular file";
    case std::filesystem::file_type::directory: return "a directory";
    case std::filesystem::file_type::character: return "a character device";
    case std::filesystem::file_type::block: return "a block device";
    case std::filesystem::file_type::fifo: return "a named pipe";
    case std::filesystem::file_type::socket: return "a socket";
    default: return "of another kind";
  }
}

}  // namespace clod::detail
