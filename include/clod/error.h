#pragma once
// Errors in clod come in three tiers (see docs/conventions.md):
//  1. Broken preconditions (programmer errors) go to CLOD_ASSERT, whose handler can be replaced.
//  2. Bad outside data (files, meshes, scenes, arguments) throws clod::Error, which carries a
//     code and a message naming the culprit, e.g. "triangle 812: vertex index 9001 >= vertex
//     count 4000". Every public function that reads outside data documents that it may throw.
//  3. Running out of a time budget is not an error: queries return what they have.
// Library code never prints and never exits.

#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>

namespace clod {

/// What went wrong with outside data. Stable numbering: tools and tests key on these.
enum class ErrorCode : std::uint16_t {
  kInvalidArgument = 1,   ///< an argument or option is out of its documented range
  kFileNotFound,          ///< the path does not exist
  kFileUnreadable,        ///< the path exists but cannot be read (permissions, a directory, I/O error)
  kFileWriteFailed,       ///< an output file could not be written or renamed into place
  kEmptyFile,             ///< the file has zero bytes
  kUnknownFormat,         ///< no reader recognises the file's format
  kParseError,            ///< the file's format is known but its content is malformed
  kNonFiniteVertex,       ///< a vertex coordinate is NaN or infinite
  kIndexOutOfRange,       ///< a triangle refers to a vertex that does not exist
  kNoTriangles,           ///< the mesh has no triangles at all
  kAllTrianglesDegenerate,///< every triangle has zero area
  kUnsupportedMesh,       ///< the mesh is valid but a stage cannot handle it (the message says why)
  kBakeTruncated,         ///< a bake file ends before its declared content
  kBakeCorrupt,           ///< a bake file's magic, section table or checksum is wrong
  kBakeVersion,           ///< a bake file was written by an incompatible format version
  kBakeMissingSection,    ///< a bake file lacks a section the caller needs
  kSceneError,            ///< a scene description is malformed (message holds the key path)
  kSimulationDiverged,    ///< a body's state became NaN/Inf (message names the body)
  kExternalToolFailed,    ///< a program we run (gnuplot) is missing or failed (message names it)
  kResourceLimit,         ///< a documented, settable limit on work or memory was reached (message names it)
};

/// Short stable name of an error code, e.g. "non_finite_vertex".
std::string_view errorCodeName(ErrorCode code) noexcept;

/// The exception thrown for bad outside data. what() is the full human-readable message.
class Error : public std::runtime_error {
public:
  Error(ErrorCode code, const std::string& message) : std::runtime_error(message), code_(code) {}
  ErrorCode code() const noexcept { return code_; }

private:
  ErrorCode code_;
};

/// Handler called when a CLOD_ASSERT fails. Default: print to stderr and abort.
using AssertHandler = void (*)(const char* condition, const char* file, int line);
/// Replaces the assert handler (e.g. to throw in tests or to log in an engine). Returns the old one.
AssertHandler setAssertHandler(AssertHandler handler) noexcept;
[[noreturn]] void assertFailed(const char* condition, const char* file, int line);

}  // namespace clod

#if defined(NDEBUG) && !defined(CLOD_ENABLE_ASSERTS)
#define CLOD_ASSERT(condition) ((void)0)
#else
#define CLOD_ASSERT(condition) \
  ((condition) ? (void)0 : ::clod::assertFailed(#condition, __FILE__, __LINE__))
#endif
