#pragma once
// The resource limits of mesh loading (MeshLoadOptions::maxVertices, maxTriangles,
// maxPolygonVertices), checked before the memory they bound is allocated: here on what a file
// declares (OBJ lines, PLY header and list counts), by the OFF reader on its header, and by the loader on the
// importer's output before copying it.

#include <cstdint>
#include <string>
#include <string_view>

#include "clod/mesh_io.h"

namespace clod::detail {

/// Throws clod::Error(kUnsupportedMesh) when count > limit, with a message saying what was
/// counted, the limit's name in MeshLoadOptions and how to get past it:
/// "<where>: <count> <what>, more than MeshLoadOptions::<option> = <limit> (raise it to load this file)".
void enforceLimit(std::uint64_t count, std::uint64_t limit, std::string_view option, std::string_view what,
                  const std::string& where);

/// Checks the counts an OBJ text (format "obj") or PLY content (looksLikePly) declares against
/// the limits, before the importer sees it: OBJ `v` lines, and `f` lines' corners (each one a
/// vertex once imported, and against maxPolygonVertices per face) and n - 2 triangles each
/// (one pass, O(size)); the PLY header's `element vertex` and `element face`
/// counts (each face taken as one triangle), which must also fit in the bytes there are
/// (kParseError otherwise: each element takes at least a byte), the header's keywords and types
/// (kParseError for others), and every list's count in the data, ASCII or binary, against
/// maxPolygonVertices (the importer sizes a list by it). Other content: nothing to check.
void checkDeclaredCounts(std::string_view text, std::string_view format, const std::string& source,
                         const MeshLoadOptions& options);

}  // namespace clod::detail
