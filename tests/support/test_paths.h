#pragma once
// Where the tests find the shared meshes, their own data files, the scenes and the built CLI:
// CLOD_SHARED_MESH_DIR, CLOD_TEST_DATA_DIR, CLOD_SCENES_DIR and CLOD_CLI_PATH, each a
// `const char*` read once from the environment variable of the same name (ctest sets them all,
// tests/CMakeLists.txt), else derived from where the test binary lies (build*/bin/ inside the
// source tree), so a runner started by hand finds them too. Every test source gets this header
// through `-include` (tests/CMakeLists.txt).
// Why not compile the paths in: an absolute path in a -D flag made every test file's compile
// command unique to its checkout, so ccache (scripts/test.sh) never hit on CI's fresh clone of the
// same sources, and the test runners were most of CI's build time.

#include <cstdlib>
#include <filesystem>
#include <map>
#include <string>
#include <system_error>

namespace clod::test {

inline const std::map<std::string, std::string>& testPaths() {
  static const std::map<std::string, std::string> paths = [] {
    std::error_code ec;
    const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
    const std::filesystem::path bin = exe.parent_path();              // <source>/build*/bin
    const std::filesystem::path source = bin.parent_path().parent_path();
    std::map<std::string, std::string> fallback = {
        {"CLOD_SHARED_MESH_DIR", (source / ".." / "shared" / "data" / "meshes").string()},
        {"CLOD_TEST_DATA_DIR", (source / "tests" / "data").string()},
        {"CLOD_SCENES_DIR", (source / "scenes").string()},
        {"CLOD_CLI_PATH", (bin / "clod").string()}};
    for (auto& [name, value] : fallback)
      if (const char* set = std::getenv(name.c_str()); set != nullptr && *set != '\0') value = set;
    return fallback;
  }();
  return paths;
}

/// The path named `name` (one of the four above); empty for any other name.
inline const char* testPath(const char* name) {
  const auto& paths = testPaths();
  const auto it = paths.find(name);
  return it == paths.end() ? "" : it->second.c_str();
}

}  // namespace clod::test

#define CLOD_SHARED_MESH_DIR (::clod::test::testPath("CLOD_SHARED_MESH_DIR"))
#define CLOD_TEST_DATA_DIR (::clod::test::testPath("CLOD_TEST_DATA_DIR"))
#define CLOD_SCENES_DIR (::clod::test::testPath("CLOD_SCENES_DIR"))
#define CLOD_CLI_PATH (::clod::test::testPath("CLOD_CLI_PATH"))
