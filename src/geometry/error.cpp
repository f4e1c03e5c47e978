#include "clod/error.h"

#include <cstdio>
#include <cstdlib>

namespace clod {

std::string_view errorCodeName(ErrorCode code) noexcept {
  switch (code) {
    case ErrorCode::kInvalidArgument: return "invalid_argument";
    case ErrorCode::kFileNotFound: return "file_not_found";
    case ErrorCode::kFileUnreadable: return "file_unreadable";
    case ErrorCode::kFileWriteFailed: return "file_write_failed";
    case ErrorCode::kEmptyFile: return "empty_file";
    case ErrorCode::kUnknownFormat: return "unknown_format";
    case ErrorCode::kParseError: return "parse_error";
    case ErrorCode::kNonFiniteVertex: return "non_finite_vertex";
    case ErrorCode::kIndexOutOfRange: return "index_out_of_range";
    case ErrorCode::kNoTriangles: return "no_triangles";
    case ErrorCode::kAllTrianglesDegenerate: return "all_triangles_degenerate";
    case ErrorCode::kUnsupportedMesh: return "unsupported_mesh";
    case ErrorCode::kBakeTruncated: return "bake_truncated";
    case ErrorCode::kBakeCorrupt: return "bake_corrupt";
    case ErrorCode::kBakeVersion: return "bake_version";
    case ErrorCode::kBakeMissingSection: return "bake_missing_section";
    case ErrorCode::kSceneError: return "scene_error";
    case ErrorCode::kSimulationDiverged: return "simulation_diverged";
    case ErrorCode::kExternalToolFailed: return "external_tool_failed";
    case ErrorCode::kResourceLimit: return "resource_limit";
  }
  return "unknown_error";
}

namespace {
void defaultAssertHandler(const char* condition, const char* file, int line) {
  std::fprintf(stderr, "clod: assertion failed: %s (%s:%d)\n", condition, file, line);
}
AssertHandler gAssertHandler = &defaultAssertHandler;
}  // namespace

AssertHandler setAssertHandler(AssertHandler handler) noexcept {
  AssertHandler old = gAssertHandler;
  gAssertHandler = handler ? handler : &defaultAssertHandler;
  return old;
}

void assertFailed(const char* condition, const char* file, int line) {
  gAssertHandler(condition, file, line);
  std::abort();
}

}  // namespace clod
