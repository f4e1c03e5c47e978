#pragma once
// The two folders `clod view` serves: the built viewer at / and the output folder at /data/.
// Maps a request target to a file inside them, refusing every path that could leave them.
#include <filesystem>
#include <string_view>

#include "http_response.h"

namespace clod::cli {

class StaticSite {
public:
  /// Both folders must exist; they are canonicalised once, here.
  StaticSite(const std::filesystem::path& viewerRoot, const std::filesystem::path& dataRoot);

  /// The answer to a GET or HEAD of `target`: the file opened for streaming, or an error page.
  /// Every path is percent-decoded and split into segments; any "." or "..", empty inner
  /// segment, NUL or backslash is refused (403) rather than normalised, so no spelling of a path
  /// climbs out of a root. The file found must still resolve inside its root (a symlink that
  /// leaves it: 403) and be a regular file (directories: their index.html, else 404).
  HttpResponse respond(std::string_view method, std::string_view target) const;

private:
  std::filesystem::path viewerRoot_;
  std::filesystem::path dataRoot_;
};

}  // namespace clod::cli
